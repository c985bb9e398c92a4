"""Writes docs/python.md, the Python API reference, from the docstrings of the installed package.

Every name of ``subfit.__all__`` is documented from the imported package (``inspect``); the
names of ``subfit.torch.__all__`` are read from the installed ``subfit/torch.py`` with ``ast``,
since importing that module needs PyTorch, so the page is the same with or without torch.
Signatures keep the annotations as written in the source (``from __future__ import
annotations``), which makes the page the same on every Python version. Docstrings are numpy
style; their sections become Markdown (field lists as bullet lists, Examples as code) and
Sphinx roles (``:func:`subfit.read```) links to the page's entries. A public name or member
without a docstring is an error: the page documents everything public.

Run after ``pip install ./crates/subfit-py`` (from the repository root)::

    python crates/subfit-py/tools/api_page.py docs/python.md

Without an argument the page goes to standard output. ``crates/subfit-py/tests/test_api_page.py``
fails when the committed page differs from what this writes.
"""

from __future__ import annotations

import ast
import inspect
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, List, Optional

REGENERATE = "python crates/subfit-py/tools/api_page.py docs/python.md"

#: Docstrings of the public names that are plain data (they cannot carry one).
DATA_DOCS = {
    "__version__": "The package's version (a string: the crate's version from its Cargo.toml).",
}

#: numpy-docstring sections whose entries are ``name : type`` lines with indented descriptions.
FIELD_SECTIONS = {"Parameters", "Other Parameters", "Returns", "Yields", "Raises", "Attributes"}

#: Signatures longer than this (characters) are written one parameter per line.
LINE = 88


@dataclass
class Param:
    """One parameter of a signature, its annotation and default as source text."""

    name: str
    kind: str  # "positional-only", "positional", "var-positional", "keyword-only", "var-keyword"
    annotation: Optional[str] = None
    default: Optional[str] = None


@dataclass
class Entry:
    """A documented name: a function, class, method or property, or a module-level value."""

    qualname: str  # "subfit.Fit.save"
    kind: str  # "function", "class", "method", "property", "data"
    doc: str
    params: Optional[List[Param]] = None  # None: no call signature is shown
    returns: Optional[str] = None
    members: List["Entry"] = field(default_factory=list)


# ------------------------------------------------------------------------------------------
# Collecting entries: the imported package (inspect) and torch.py's source (ast)
# ------------------------------------------------------------------------------------------
def _unquote(text: str) -> str:
    """``"'Surface'"`` (a quoted forward reference) → ``"Surface"``."""
    return text[1:-1] if len(text) > 1 and text[0] == text[-1] and text[0] in "'\"" else text


def _annotation_text(a: object) -> Optional[str]:
    if a is inspect.Parameter.empty:
        return None
    if isinstance(a, str):
        return _unquote(a)
    forward = getattr(a, "__forward_arg__", None)
    return _unquote(forward) if forward is not None else inspect.formatannotation(a)


def _inspect_params(obj: Callable, drop_self: bool) -> tuple:
    sig = inspect.signature(obj)
    kinds = {
        inspect.Parameter.POSITIONAL_ONLY: "positional-only",
        inspect.Parameter.POSITIONAL_OR_KEYWORD: "positional",
        inspect.Parameter.VAR_POSITIONAL: "var-positional",
        inspect.Parameter.KEYWORD_ONLY: "keyword-only",
        inspect.Parameter.VAR_KEYWORD: "var-keyword",
    }
    params = [
        Param(
            p.name,
            kinds[p.kind],
            _annotation_text(p.annotation),
            None if p.default is inspect.Parameter.empty else repr(p.default),
        )
        for p in sig.parameters.values()
    ]
    if drop_self and params and params[0].name in ("self", "cls"):
        params = params[1:]
    return params, _annotation_text(sig.return_annotation)


def _require_doc(qualname: str, doc: Optional[str]) -> str:
    if not doc or not doc.strip():
        raise SystemExit(f"api_page: {qualname} is public and has no docstring; write one")
    return inspect.cleandoc(doc)


def _has_section(doc: str, name: str) -> bool:
    return re.search(rf"^{name}\n-{{{len(name)}}}$", doc, re.M) is not None


def _inspect_class(qualname: str, cls: type) -> Entry:
    doc = _require_doc(qualname, cls.__doc__)
    entry = Entry(qualname, "class", doc)
    # A class whose docstring documents Parameters is built by the user: show its constructor.
    # The others (Fit, Mesh, …) are results that functions return.
    if _has_section(doc, "Parameters"):
        entry.params, _ = _inspect_params(cls.__init__, drop_self=True)
    for name, member in vars(cls).items():
        if name.startswith("_"):
            continue
        mq = f"{qualname}.{name}"
        if isinstance(member, property):
            entry.members.append(Entry(mq, "property", _require_doc(mq, member.__doc__)))
        elif isinstance(member, (staticmethod, classmethod)) or inspect.isfunction(member):
            fn = member.__func__ if isinstance(member, (staticmethod, classmethod)) else member
            params, returns = _inspect_params(fn, drop_self=not isinstance(member, staticmethod))
            entry.members.append(Entry(mq, "method", _require_doc(mq, fn.__doc__), params, returns))
    return entry


def package_entries(package: object) -> List[Entry]:
    """Entries for every name of ``package.__all__``, in that order."""
    out = []
    for name in package.__all__:  # type: ignore[attr-defined]
        qualname = f"{package.__name__}.{name}"  # type: ignore[attr-defined]
        obj = getattr(package, name)
        if inspect.isclass(obj):
            out.append(_inspect_class(qualname, obj))
        elif callable(obj):
            params, returns = _inspect_params(obj, drop_self=False)
            out.append(Entry(qualname, "function", _require_doc(qualname, obj.__doc__), params, returns))
        else:
            if name not in DATA_DOCS:
                raise SystemExit(f"api_page: {qualname} is plain data: add its description to DATA_DOCS")
            out.append(Entry(qualname, "data", DATA_DOCS[name]))
    return out


def _ast_params(fn: ast.FunctionDef, drop_self: bool) -> tuple:
    a = fn.args
    text = lambda node: None if node is None else _unquote(ast.unparse(node))  # noqa: E731
    positional = a.posonlyargs + a.args
    defaults = [None] * (len(positional) - len(a.defaults)) + list(a.defaults)
    params = [
        Param(p.arg, "positional-only" if i < len(a.posonlyargs) else "positional", text(p.annotation), text(d))
        for i, (p, d) in enumerate(zip(positional, defaults))
    ]
    if a.vararg:
        params.append(Param(a.vararg.arg, "var-positional", text(a.vararg.annotation)))
    params += [
        Param(p.arg, "keyword-only", text(p.annotation), text(d)) for p, d in zip(a.kwonlyargs, a.kw_defaults)
    ]
    if a.kwarg:
        params.append(Param(a.kwarg.arg, "var-keyword", text(a.kwarg.annotation)))
    if drop_self and params and params[0].name in ("self", "cls"):
        params = params[1:]
    return params, text(fn.returns)


def _ast_class(qualname: str, node: ast.ClassDef) -> Entry:
    doc = _require_doc(qualname, ast.get_docstring(node, clean=False))
    entry = Entry(qualname, "class", doc)
    init = next((n for n in node.body if isinstance(n, ast.FunctionDef) and n.name == "__init__"), None)
    if init is not None and _has_section(doc, "Parameters"):
        entry.params, _ = _ast_params(init, drop_self=True)
    for n in node.body:
        if not isinstance(n, ast.FunctionDef) or n.name.startswith("_"):
            continue
        mq = f"{qualname}.{n.name}"
        mdoc = _require_doc(mq, ast.get_docstring(n, clean=False))
        decorators = {ast.unparse(d) for d in n.decorator_list}
        if "property" in decorators:
            entry.members.append(Entry(mq, "property", mdoc))
        else:
            params, returns = _ast_params(n, drop_self="staticmethod" not in decorators)
            entry.members.append(Entry(mq, "method", mdoc, params, returns))
    return entry


def source_entries(path: Path, module: str) -> tuple:
    """``(module docstring, entries of its __all__)`` read from ``path`` without importing it."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names = None
    defs = {}
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets):
            names = ast.literal_eval(node.value)
        elif isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            defs[node.name] = node
    if names is None:
        raise SystemExit(f"api_page: {path} has no __all__")
    out = []
    for name in names:
        qualname = f"{module}.{name}"
        node = defs.get(name)
        if node is None:
            raise SystemExit(f"api_page: {qualname} is in __all__ but not defined at the top of {path}")
        if isinstance(node, ast.ClassDef):
            out.append(_ast_class(qualname, node))
        else:
            params, returns = _ast_params(node, drop_self=False)
            doc = _require_doc(qualname, ast.get_docstring(node, clean=False))
            out.append(Entry(qualname, "function", doc, params, returns))
    return _require_doc(module, ast.get_docstring(tree, clean=False)), out


# ------------------------------------------------------------------------------------------
# Writing Markdown
# ------------------------------------------------------------------------------------------
def signature(name: str, params: List[Param], returns: Optional[str]) -> str:
    """``name(params) -> returns`` with ``/`` and ``*`` markers, one parameter per line when long."""
    parts = []
    star = False
    for i, p in enumerate(params):
        if p.kind == "keyword-only" and not star:
            parts.append("*")
            star = True
        if p.kind == "var-positional":
            star = True
        s = {"var-positional": "*", "var-keyword": "**"}.get(p.kind, "") + p.name
        if p.annotation is not None:
            s += f": {p.annotation}"
        if p.default is not None:
            s += f" = {p.default}" if p.annotation is not None else f"={p.default}"
        parts.append(s)
        last_posonly = p.kind == "positional-only" and (i + 1 == len(params) or params[i + 1].kind != "positional-only")
        if last_posonly:
            parts.append("/")
    tail = f" -> {returns}" if returns else ""
    one = f"{name}({', '.join(parts)}){tail}"
    if len(one) <= LINE:
        return one
    return f"{name}(\n" + "".join(f"    {s},\n" for s in parts) + f"){tail}"


class Linker:
    """Turns Sphinx roles into Markdown links to the page's entries (or code when unknown)."""

    ROLE = re.compile(r":(?:py:)?(?:func|class|meth|attr|mod|data|obj|exc):`(~?)([^`]+)`")

    def __init__(self, entries: List[Entry]) -> None:
        self.anchors = set()
        for e in entries:
            self.anchors.add(e.qualname)
            self.anchors.update(m.qualname for m in e.members)

    def resolve(self, target: str, scope: str) -> Optional[str]:
        """The anchor ``target`` names, seen from the entry ``scope`` (``subfit.Fit.save``)."""
        scopes = scope.split(".")
        for k in range(len(scopes), 0, -1):
            cand = ".".join(scopes[:k] + [target])
            if cand in self.anchors:
                return cand
        return target if target in self.anchors else None

    def inline(self, text: str, scope: str) -> str:
        """Sphinx roles → links; reStructuredText's double-backquoted code → Markdown's single."""

        def role(m: re.Match) -> str:
            tilde, target = m.group(1), m.group(2).strip()
            shown = target.rsplit(".", 1)[-1] if tilde else target
            anchor = self.resolve(target, scope)
            return f"[`{shown}`](#{anchor})" if anchor else f"`{shown}`"

        text = self.ROLE.sub(role, text)
        return re.sub(r"``([^`]+?)``", lambda m: "`" + " ".join(m.group(1).split()) + "`", text)


def _sections(doc: str) -> List[tuple]:
    """``[(title or None, lines)]``: the docstring split at numpy section headers."""
    lines = doc.splitlines()
    out: List[tuple] = [(None, [])]
    i = 0
    while i < len(lines):
        if i + 1 < len(lines) and lines[i].strip() and re.fullmatch(r"-{3,}", lines[i + 1].strip()) \
                and len(lines[i + 1].strip()) == len(lines[i].strip()):
            out.append((lines[i].strip(), []))
            i += 2
            continue
        out[-1][1].append(lines[i])
        i += 1
    return [(t, ls) for t, ls in out if t is not None or any(s.strip() for s in ls)]


def _field_list(lines: List[str]) -> List[str]:
    """``name : type`` lines with indented descriptions → a bullet list."""
    items: List[tuple] = []
    for line in lines:
        if not line.strip():
            if items:
                items[-1][1].append("")
            continue
        if not line.startswith(" "):
            items.append((line.strip(), []))
        elif items:
            items[-1][1].append(line.strip())
    out = []
    for head, desc in items:
        name, _, typ = head.partition(" : ")
        label = f"`{name.strip()}`" + (f" ({typ.strip()})" if typ else "")
        paragraphs = [[]]
        for d in desc:
            if d:
                paragraphs[-1].append(d)
            elif paragraphs[-1]:
                paragraphs.append([])
        text = "\n\n  ".join(" ".join(p) for p in paragraphs if p)
        out.append(f"- {label}" + (f": {text}" if text else ""))
    return out


def _prose(lines: List[str]) -> List[str]:
    """Free text: kept line by line (lists and paragraphs are Markdown already); doctest lines
    (``>>>`` to the next blank line) become code blocks."""
    out: List[str] = []
    in_code = False
    for line in lines:
        doctest = line.lstrip().startswith(">>> ")
        if doctest and not in_code:
            out.append("```python")
            in_code = True
        elif in_code and not line.strip():
            out.append("```")
            in_code = False
        if in_code:
            out.append(re.sub(r"\s*# doctest:.*$", "", line.strip()))
        else:
            out.append(line)
    if in_code:
        out.append("```")
    return out


def render_doc(doc: str, scope: str, linker: Linker) -> List[str]:
    """A numpy docstring as Markdown lines (roles and code converted section by section, so
    markup that wraps a line is converted too; doctest examples become code blocks)."""
    out: List[str] = []
    for title, lines in _sections(doc):
        while lines and not lines[-1].strip():
            lines = lines[:-1]
        if title is not None:
            out += ["", f"**{title}**", ""]
        lines = linker.inline("\n".join(lines), scope).split("\n")
        out += _field_list(lines) if title in FIELD_SECTIONS else _prose(lines)
    return out


def _heading(e: Entry, level: str) -> List[str]:
    kind = {"function": "function", "class": "class", "method": "method", "property": "property", "data": ""}[e.kind]
    return [f'{level} <a id="{e.qualname}"></a>`{e.qualname}`' + (f" ({kind})" if kind else ""), ""]


def render_entry(e: Entry, linker: Linker) -> List[str]:
    """One entry (and its members) as Markdown lines."""
    out = _heading(e, "###")
    if e.params is not None:
        out += ["```python", signature(e.qualname, e.params, e.returns), "```", ""]
    out += render_doc(e.doc, e.qualname, linker)
    for m in e.members:
        out += ["", *_heading(m, "####")]
        if m.params is not None:
            short = m.qualname.rsplit(".", 2)[-2] + "." + m.qualname.rsplit(".", 1)[-1]
            out += ["```python", signature(short, m.params, m.returns), "```", ""]
        out += render_doc(m.doc, m.qualname, linker)
    return out + [""]


def _contents(module: str, entries: List[Entry]) -> List[str]:
    return [f"- `{module}`: " + ", ".join(f"[`{e.qualname.rsplit('.', 1)[-1]}`](#{e.qualname})" for e in entries)]


def render(package: object, torch_doc: str, torch_entries: List[Entry]) -> str:
    """The whole page."""
    entries = package_entries(package)
    linker = Linker(entries + torch_entries)
    out = [
        "# Python API reference",
        "",
        f"<!-- Generated from the docstrings by crates/subfit-py/tools/api_page.py; do not edit."
        f" After changing a docstring: pip install ./crates/subfit-py && {REGENERATE} -->",
        "",
        "The package `subfit` (`pip install ./crates/subfit-py`; the tutorial is",
        "[Python and PyTorch](guide/python-and-pytorch.md)). Every public name, its signature",
        "and its docstring (`help(subfit.fit)` shows the same text).",
        "",
        *_contents("subfit", entries),
        *_contents("subfit.torch", torch_entries),
        "",
        "## `subfit`",
        "",
        *render_doc(_require_doc("subfit", package.__doc__), "subfit", linker),
        "",
    ]
    for e in entries:
        out += render_entry(e, linker)
    out += ["## `subfit.torch`", "", *render_doc(torch_doc, "subfit.torch", linker), ""]
    for e in torch_entries:
        out += render_entry(e, linker)
    text = "\n".join(out)
    text = re.sub(r"\n{3,}", "\n\n", text)
    return text.rstrip("\n") + "\n"


def page() -> str:
    """The page for the installed ``subfit`` (torch's part read from its source)."""
    import subfit

    torch_path = Path(subfit.__file__).with_name("torch.py")
    torch_doc, torch_entries = source_entries(torch_path, "subfit.torch")
    return render(subfit, torch_doc, torch_entries)


def main(argv: List[str]) -> int:
    """``api_page.py [OUT]``: writes the page to OUT, or to standard output."""
    text = page()
    if len(argv) > 1:
        Path(argv[1]).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
