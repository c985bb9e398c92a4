#!/usr/bin/env python3
"""Functions longer than a limit in the library sources of the workspace's crates.

STYLE.md asks for functions that read in one sitting; the structure review set the bar at 150
lines, counted from the line of `fn` to the line of its closing brace (doc comments and
attributes above it not counted). Files under `src/` of each crate are read; `#[cfg(test)]`
modules, integration tests, benches and examples are left out (a test may be long).

Comments and string literals are blanked first, line breaks kept, so braces inside them do not
count and the line numbers stay the file's.

It prints `LINES path:line name` for every function over the limit, longest first, then a
count, and exits 1 if there is any, 0 otherwise.

Usage: tools/long_functions.py [--max N] [CRATE_DIR ...]   (default: 150, every crates/*/)
"""

import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rust_source import blank, matching_brace  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

FN = re.compile(r"\bfn\s+(\w+)")
CFG_TEST = re.compile(r"#\[cfg\(test\)\]\s*(?:#\[[^\]]*\]\s*)*(?:pub(?:\([^)]*\))?\s+)?mod\s+\w+\s*\{")


def test_spans(text):
    """(start, end) offsets of `#[cfg(test)] mod x { … }` bodies."""
    spans = []
    for m in CFG_TEST.finditer(text):
        spans.append((m.start(), matching_brace(text, m.end() - 1)))
    return spans


def long_functions(path, limit):
    text = blank(open(path, encoding="utf-8").read())
    skip = test_spans(text)
    found = []
    for m in FN.finditer(text):
        if any(a <= m.start() <= b for a, b in skip):
            continue
        # The body opens at the first `{` before any `;` (a declaration without a body ends at `;`).
        # Semicolons inside brackets (`[f64; 3]`) are not the end of a declaration.
        j, depth = m.end(), 0
        while j < len(text) and not (depth == 0 and text[j] in "{;"):
            depth += {"(": 1, "[": 1, ")": -1, "]": -1}.get(text[j], 0)
            j += 1
        if j >= len(text) or text[j] == ";":
            continue
        close = matching_brace(text, j)
        first = text.count("\n", 0, m.start()) + 1
        last = text.count("\n", 0, close) + 1
        lines = last - first + 1
        if lines > limit:
            found.append((lines, path, first, m.group(1)))
    return found


def main(argv):
    limit = 150
    if argv[:1] == ["--max"]:
        limit, argv = int(argv[1]), argv[2:]
    crates = argv or sorted(
        os.path.join(ROOT, "crates", d)
        for d in os.listdir(os.path.join(ROOT, "crates"))
        if os.path.isdir(os.path.join(ROOT, "crates", d, "src"))
    )
    found = []
    for crate in crates:
        for dirpath, dirnames, files in os.walk(os.path.join(crate, "src")):
            dirnames[:] = [d for d in dirnames if d != "target"]
            for f in files:
                if f.endswith(".rs"):
                    found += long_functions(os.path.join(dirpath, f), limit)
    for lines, path, line, name in sorted(found, reverse=True):
        print(f"{lines} {os.path.relpath(path, ROOT)}:{line} {name}")
    print(f"{len(found)} function(s) over {limit} lines")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
