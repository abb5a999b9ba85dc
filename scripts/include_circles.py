#!/usr/bin/env python3
"""Lists the circles of includes between the project's units and exits 1 if there is one.

A unit is a header and its source file taken together (geometry/image/image.h and
image.cpp are the unit geometry/image/image); unit A depends on unit B when either of A's
files includes one of B's with a quoted #include. A circle is a set of units that depend
on each other, directly or through others (a strongly connected component of more than
one unit). Only files git tracks are read, so build folders do not count.

    python3 scripts/include_circles.py [ROOT]
"""
import os
import re
import subprocess
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
SOURCES = (".h", ".hpp", ".cpp", ".cc")


def tracked_sources(root):
    out = subprocess.run(["git", "-C", root, "ls-files"], check=True, capture_output=True, text=True).stdout
    return [f for f in out.split() if f.endswith(SOURCES)]


def unit_graph(root, files):
    """unit -> set of units it includes (relative paths without extension)."""
    known = set(files)
    unit = lambda f: os.path.splitext(f)[0]
    graph = {unit(f): set() for f in files}
    for f in files:
        with open(os.path.join(root, f), encoding="utf-8", errors="replace") as fh:
            for inc in INCLUDE.findall(fh.read()):
                if inc in known and unit(inc) != unit(f):
                    graph[unit(f)].add(unit(inc))
    return graph


def circles(graph):
    """The strongly connected components of more than one unit (Tarjan, iterative)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []
    counter = 0
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                elif w in on_stack:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    found.append(sorted(comp))
    return sorted(found)


def main(argv):
    root = argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    graph = unit_graph(root, tracked_sources(root))
    found = circles(graph)
    for comp in found:
        members = set(comp)
        edges = [f"{a} -> {b}" for a in comp for b in sorted(graph[a] & members)]
        print("circle: " + ", ".join(comp) + "\n  " + "\n  ".join(edges))
    print(f"{len(graph)} units, {len(found)} circles")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
