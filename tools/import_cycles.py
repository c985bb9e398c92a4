#!/usr/bin/env python3
"""Import circles between the files (modules) of each crate of the workspace.

STYLE.md rule 7 and the structure review ask for modules that read one way: a file that uses
another must not be used back by it, directly or through others. This script builds, for every
crate under crates/ (or the crate directories given), the graph "module A names an item of
module B" from

  * `use crate::…`, `use super::…`, `use self::…` and `use child::…` (a child module of A),
    with `{…}` groups expanded;
  * paths written in code: `crate::a::f(…)`, `super::g`, `self::h`;

each path resolved to the file that defines the item: a `pub use` (or any `use`) of the
module named is followed, so `crate::Options` re-exported by lib.rs from options.rs is an edge
to options.rs, not to lib.rs. `mod` declarations are not edges (they nest, they do not
import). Comments, doc comments and modules under `#[cfg(test)]` (inline `mod tests { … }` and
test-only files) are left out: a test may look at anything.

It prints every strongly connected component of more than one module (a circle) with the
edges inside it, and exits 1 if there is any, 0 otherwise.

Usage: tools/import_cycles.py [CRATE_DIR ...]   (default: every crates/*/ with a src/)
"""

import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rust_source import blank, matching_brace  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def strip_comments(text):
    """The source without comments and string/char literals (which may hold `crate::`)."""
    return blank(text)


CFG_TEST_MOD = re.compile(r"#\[cfg\(test\)\]\s*(?:#\[[^\]]*\]\s*)*(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*([;{])")
MOD_DECL = re.compile(r"((?:#\[[^\]]*\]\s*)*)(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;")
USE = re.compile(r"\buse\s+([^;]+);")
INLINE = re.compile(r"(?<![\w:])((?:crate|super|self)(?:::(?:super|\w+))+)")


def without_test_modules(text):
    """`text` with inline `#[cfg(test)] mod x { … }` bodies removed; also the names of
    test-only module files (`#[cfg(test)] mod x;`)."""
    test_files = set()
    while True:
        m = CFG_TEST_MOD.search(text)
        if not m:
            return text, test_files
        if m.group(2) == ";":
            test_files.add(m.group(1))
            text = text[: m.start()] + text[m.end():]
        else:
            close = matching_brace(text, m.end() - 1)
            text = text[: m.start()] + text[close + 1:]


def expand_use(tree):
    """`a::{b, c::{d, e as f}}` → [(['a','b'], 'b'), (['a','c','d'], 'd'), (['a','c','e'], 'f')]."""
    tree = re.sub(r"\s+as\s+", "@", tree.strip())
    tree = re.sub(r"\s+", "", tree).lstrip(":")
    results = []

    def split_top(s):
        parts, depth, cur = [], 0, ""
        for ch in s:
            depth += (ch == "{") - (ch == "}")
            if ch == "," and depth == 0:
                parts.append(cur)
                cur = ""
            else:
                cur += ch
        return parts + [cur]

    def walk(prefix, s):
        for p in split_top(s):
            if not p:
                continue
            brace = p.find("{")
            if brace >= 0 and p.endswith("}"):
                head = [x for x in p[:brace].split("::") if x]
                walk(prefix + head, p[brace + 1:-1])
                continue
            p, _, alias = p.partition("@")
            segs = prefix + [x for x in p.split("::") if x]
            if segs and segs[-1] == "self":
                segs = segs[:-1]
            if segs:
                results.append((segs, alias or segs[-1]))

    walk([], tree)
    return results


class Crate:
    def __init__(self, src):
        self.src = src
        self.files = {}  # module path tuple -> file
        self.uses = {}  # module path -> list of (absolute segs, name)
        self.inline = {}  # module path -> list of absolute segs
        self.test_only = set()
        for root_file in ("lib.rs", "main.rs"):
            p = os.path.join(src, root_file)
            if os.path.exists(p):
                self.load((), p, os.path.dirname(p))
        # binaries under src/bin/ are crate roots of their own: left out

    def load(self, path, file, child_dir):
        self.files[path] = file
        text = strip_comments(open(file, encoding="utf-8").read())
        text, test_files = without_test_modules(text)
        # child files
        for m in MOD_DECL.finditer(text):
            attrs, name = m.group(1), m.group(2)
            pm = re.search(r'#\[path\s*=\s*"([^"]*)"\]', attrs)
            if pm:
                f = os.path.join(os.path.dirname(file), pm.group(1))
            else:
                f = os.path.join(child_dir, name + ".rs")
                if not os.path.exists(f):
                    f = os.path.join(child_dir, name, "mod.rs")
            if not os.path.exists(f):
                continue
            base = os.path.basename(f)
            sub_dir = os.path.dirname(f) if base in ("mod.rs",) else os.path.join(os.path.dirname(f), base[:-3])
            self.load(path + (name,), f, sub_dir)
        for name in test_files:
            self.test_only.add(path + (name,))
        self.text = getattr(self, "text", {})
        self.text[path] = text

    def children(self, path):
        return {p[-1] for p in self.files if len(p) == len(path) + 1 and p[: len(path)] == path}

    def absolute(self, path, segs):
        """`segs` as written in module `path` → an absolute module-path list, or None for an
        external crate."""
        if not segs:
            return None
        cur = list(path)
        i = 0
        if segs[0] == "crate":
            cur, i = [], 1
        elif segs[0] in ("self", "super"):
            while i < len(segs) and segs[i] in ("self", "super"):
                if segs[i] == "super":
                    if not cur:
                        return None
                    cur.pop()
                i += 1
        elif segs[0] in self.children(path):
            pass
        else:
            return None
        return cur + list(segs[i:])

    def parse(self):
        for path, text in self.text.items():
            uses, inline = [], []
            for m in USE.finditer(text):
                for segs, name in expand_use(m.group(1)):
                    a = self.absolute(path, segs)
                    if a is not None:
                        uses.append((a, name))
            for m in INLINE.finditer(USE.sub("", text)):
                a = self.absolute(path, m.group(1).split("::"))
                if a is not None:
                    inline.append(a)
            self.uses[path] = uses
            self.inline[path] = inline

    def resolve(self, segs, depth=0):
        """The module (file) that defines the item named by absolute `segs`."""
        segs = [s for s in segs if s != "*"]
        k = len(segs)
        while k > 0 and tuple(segs[:k]) not in self.files:
            k -= 1
        module = tuple(segs[:k])
        rest = segs[k:]
        if not rest or depth > 20:
            return module
        for target, name in self.uses.get(module, []):
            if name == rest[0] and target != segs[: k] + [rest[0]]:
                return self.resolve(target + rest[1:], depth + 1)
        return module

    def edges(self):
        out = {}
        for path in self.text:
            if path in self.test_only:
                continue
            targets = set()
            for a, _ in self.uses[path]:
                targets.add(self.resolve(a))
            for a in self.inline[path]:
                targets.add(self.resolve(a))
            targets.discard(path)
            out[path] = {t for t in targets if t in self.files and t not in self.test_only}
        return out


def circles(edges):
    """Strongly connected components of more than one node (Tarjan)."""
    index, low, stack, on, comps = {}, {}, [], set(), []
    counter = [0]
    sys.setrecursionlimit(10000)

    def strong(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                comps.append(sorted(comp))

    for v in sorted(edges):
        if v not in index:
            strong(v)
    return comps


def name(path):
    return "::".join(path) if path else "crate"


def main(argv):
    dirs = argv or sorted(
        os.path.join(ROOT, "crates", d)
        for d in os.listdir(os.path.join(ROOT, "crates"))
        if os.path.isdir(os.path.join(ROOT, "crates", d, "src"))
    )
    found = 0
    for d in dirs:
        crate = Crate(os.path.join(d, "src"))
        crate.parse()
        edges = crate.edges()
        for comp in circles(edges):
            found += 1
            members = set(comp)
            inside = sorted(
                f"{name(a)} -> {name(b)}" for a in comp for b in edges[a] if b in members
            )
            print(f"{os.path.basename(d)}: circle of {len(comp)} modules: {', '.join(name(c) for c in comp)}")
            for e in inside:
                print(f"    {e}")
    print(f"{found} import circle(s)")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
