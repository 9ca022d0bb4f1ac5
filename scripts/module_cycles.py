#!/usr/bin/env python3
"""File-level import graph of a Rust crate's `src/` and its dependency cycles (strongly
connected components of more than one file). `module_cycles.py [SRC]` prints each cycle.

An edge a -> b means a file mentions `crate::path` (or `super::`/`self::` paths) that
resolves to file b (the longest module prefix that is a file). Submodule declarations
(`mod x;`) are not edges: a parent that only declares a child does not depend on it, and
`#[cfg(test)]` modules are left out (a test may use any module). Exits with 1 when there is
a cycle: `tests/architecture.rs` runs it."""
import os, re, sys

src = sys.argv[1] if len(sys.argv) > 1 else "src"
files = {}
for root, _, names in os.walk(src):
    for n in names:
        if n.endswith(".rs"):
            p = os.path.join(root, n)
            rel = os.path.relpath(p, src)[:-3].split(os.sep)
            if rel[-1] == "mod":
                rel = rel[:-1]
            if rel in (["lib"], ["main"]):
                rel = []
            files[tuple(rel)] = p

def resolve(parts):
    for k in range(len(parts), 0, -1):
        if tuple(parts[:k]) in files:
            return tuple(parts[:k])
    return None

def without_tests(text):
    """The text without its `#[cfg(test)] mod ... { ... }` blocks (braces counted)."""
    while True:
        m = re.search(r"#\[cfg\(test\)\]\s*mod\s+\w+\s*\{", text)
        if not m:
            return text
        depth, k = 1, m.end()
        while depth and k < len(text):
            depth += {"{": 1, "}": -1}.get(text[k], 0)
            k += 1
        text = text[: m.start()] + text[k:]

edges = {m: set() for m in files}
for mod, path in files.items():
    text = open(path).read()
    text = without_tests(re.sub(r"//[^\n]*", "", text))
    for m in re.finditer(r"\b(crate|super)((?:::[A-Za-z_][A-Za-z0-9_]*)+)", text):
        parts = m.group(2).split("::")[1:]
        if m.group(1) == "crate":
            full = parts
        else:
            full = list(mod[:-1]) + parts
        target = resolve(full)
        if target is not None and target != mod and target != ():
            edges[mod].add(target)

# Tarjan's strongly connected components
index, low, on, stack, out = {}, {}, set(), [], []
counter = [0]
def strong(v):
    index[v] = low[v] = counter[0]; counter[0] += 1
    stack.append(v); on.add(v)
    for w in edges[v]:
        if w not in index:
            strong(w); low[v] = min(low[v], low[w])
        elif w in on:
            low[v] = min(low[v], index[w])
    if low[v] == index[v]:
        comp = []
        while True:
            w = stack.pop(); on.discard(w); comp.append(w)
            if w == v: break
        if len(comp) > 1:
            out.append(comp)
sys.setrecursionlimit(10000)
for v in edges:
    if v not in index:
        strong(v)
print(f"{len(files)} files, {sum(len(e) for e in edges.values())} import edges, {len(out)} cycles")
for comp in out:
    print(f"  cycle of {len(comp)}: " + ", ".join(sorted("::".join(c) for c in comp)))
sys.exit(1 if out else 0)
