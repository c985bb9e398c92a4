"""docs/python.md is the page crates/subfit-py/tools/api_page.py writes from the installed
package's docstrings, and the examples in those docstrings run as written (numpy-only; the
examples of ``subfit.torch`` run in test_torch.py)."""

import doctest
import importlib
import importlib.util
import re
import sys

import pytest

import subfit
from conftest import REPO

PAGE = REPO / "docs" / "python.md"


def api_page():
    spec = importlib.util.spec_from_file_location("api_page", REPO / "crates" / "subfit-py" / "tools" / "api_page.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def test_the_committed_page_is_generated_from_the_docstrings(tmp_path):
    tool = api_page()
    out = tmp_path / "python.md"
    assert tool.main(["api_page.py", str(out)]) == 0
    fresh = out.read_text(encoding="utf-8")
    committed = PAGE.read_text(encoding="utf-8") if PAGE.is_file() else ""
    if fresh != committed:
        diff = [f"{i + 1}: {a!r} != {b!r}" for i, (a, b) in enumerate(zip(committed.splitlines(), fresh.splitlines()))
                if a != b][:5]
        pytest.fail(
            "docs/python.md differs from the docstrings of the installed subfit (first differing lines: "
            f"{diff or 'one is a prefix of the other'}). Regenerate it from the repository root: "
            f"pip install ./crates/subfit-py && {tool.REGENERATE}"
        )


def test_every_public_name_is_on_the_page():
    # Independent of the generator: each name of __all__ (and of subfit.torch's, read from
    # its source) has an entry with its anchor.
    import ast
    from pathlib import Path

    text = PAGE.read_text(encoding="utf-8")
    tree = ast.parse(Path(subfit.__file__).with_name("torch.py").read_text(encoding="utf-8"))
    torch_all = next(
        ast.literal_eval(n.value) for n in tree.body
        if isinstance(n, ast.Assign) and any(getattr(t, "id", None) == "__all__" for t in n.targets)
    )
    names = [f"subfit.{n}" for n in subfit.__all__] + [f"subfit.torch.{n}" for n in torch_all]
    missing = [n for n in names if f'<a id="{n}"></a>' not in text]
    assert not missing, missing
    assert "limit_quads" in text
    # reStructuredText left unconverted.
    assert not re.search(r"(?<!`)``(?!`)|:(func|class|meth|attr):`", text)


@pytest.mark.parametrize("module", ["subfit._fit", "subfit._io", "subfit._sequence", "subfit._surface"])
def test_docstring_examples_run(module, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # examples write files into the working directory
    mod = importlib.import_module(module)
    tests = [t for t in doctest.DocTestFinder().find(mod) if t.examples]
    assert tests, f"{module} has no examples"
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for t in tests:
        runner.run(t)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples of {module} failed (printed above)"
