#!/usr/bin/env python3
"""Lists file-local functions of the same name in two files of one unity-batched target
and exits 1 if there is one.

A unity batch (cmake/unity.cmake) compiles several files as one, so their unnamed
namespaces merge: two file-local helpers of the same name become one overload set, where a
call may quietly take the other file's helper, or fail to compile depending on how the
files fall into batches. Each folder below is one target's files, and the fuzz project's
readers (fuzz/targets.cmake) are one more; a function is
file-local when it is defined at the top level of an unnamed namespace (`namespace {` ...
`}  // namespace`, as clang-format writes it), or anywhere in a test file (tests define
their helpers in unnamed namespaces).

    python3 scripts/unity_names.py [ROOT]
"""
import collections
import glob
import os
import re
import sys

# One entry per unity-batched target: the folder of its files, whether to look below it,
# and the subfolders whose files the target never batches (splat's rasterizer).
TARGETS = [
    ("geometry", True, ()), ("splat", True, ("splat/raster",)), ("nbv", False, ()), ("nbv/eval", False, ()),
    ("report", False, ()), ("apps", False, ()), ("python/src", False, ()),
    ("tests/geometry", True, ()), ("tests/splat", True, ()), ("tests/nbv", True, ()), ("tests/apps", True, ()),
    ("tests/report", True, ()),
]
# A definition's first line: a return type, the name and "(", then either no ";" (the
# parameters or the body go on below) or a whole one-line body "{ ... }".
DEFINITION = re.compile(
    r"^(?!TEST|static_assert|using|return|namespace|struct|class|enum|template|typedef|#|else|case)"
    r"[A-Za-z_][\w:<>,\*& ]*[\s\*&]([a-zA-Z_]\w*)\((?:[^;]*|.*\)[^;{]*\{.*\}\s*)$")


def local_functions(path, whole_file):
    names = set()
    depth = 0  # unnamed namespaces open at this line
    with open(path, encoding="utf-8", errors="replace") as fh:
        for line in fh:
            if re.match(r"^namespace\s*\{", line):
                depth += 1
                continue
            if re.match(r"^\}\s*//\s*namespace\s*$", line) and depth > 0:
                depth -= 1
                continue
            if depth > 0 or whole_file:
                m = DEFINITION.match(line)
                if m:
                    names.add(m.group(1))
    return names


def fuzz_readers(root):
    """The readers the fuzz project batches (SARESGS_FUZZ_READERS in fuzz/targets.cmake)."""
    path = os.path.join(root, "fuzz", "targets.cmake")
    if not os.path.exists(path):
        return []
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    m = re.search(r"set\(SARESGS_FUZZ_READERS([^)]*)\)", text)
    return re.findall(r"[\w/.-]+\.cpp", m.group(1)) if m else []


def clashes(root):
    groups = []  # (name, files)
    for folder, recursive, unbatched in TARGETS:
        pattern = os.path.join(root, folder, "**", "*.cpp") if recursive else os.path.join(root, folder, "*.cpp")
        files = [os.path.relpath(p, root) for p in sorted(glob.glob(pattern, recursive=recursive))]
        files = [f for f in files if not f.startswith(tuple(u + "/" for u in unbatched))]
        groups.append((folder, files))
    groups.append(("fuzz readers", fuzz_readers(root)))
    found = []
    for name_of_group, files in groups:
        defined = collections.defaultdict(set)
        for rel in files:
            for name in local_functions(os.path.join(root, rel), whole_file=rel.startswith("tests")):
                defined[name].add(rel)
        for name, where in sorted(defined.items()):
            if len(where) > 1:
                found.append((name_of_group, name, sorted(where)))
    return found


def main(argv):
    root = argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    found = clashes(root)
    for folder, name, files in found:
        print(f"{folder}: {name} is defined file-locally in " + ", ".join(files))
    print(f"{len(found)} names defined file-locally in more than one file of a unity target")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
