#!/usr/bin/env python3
"""Lists file-local functions of the same name in two files of one unity-batched target
and exits 1 if there is one.

A unity batch (cmake/unity.cmake) compiles several files as one, so their unnamed
namespaces merge: two file-local helpers of the same name become one overload set, where a
call may quietly take the other file's helper, or fail to compile depending on how the
files fall into batches. Each folder below is one target's files; a function is
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

# One entry per unity-batched target: the folder of its files and whether to look below it.
TARGETS = [
    ("nbv", False), ("nbv/eval", False), ("report", False), ("apps", False), ("python/src", False),
    ("tests/geometry", True), ("tests/splat", True), ("tests/nbv", True), ("tests/apps", True),
    ("tests/report", True),
]
DEFINITION = re.compile(
    r"^(?!TEST|static_assert|using|return|namespace|struct|class|enum|template|typedef|#|else|case)"
    r"[A-Za-z_][\w:<>,\*& ]*[\s\*&]([a-zA-Z_]\w*)\([^;]*$")


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


def clashes(root):
    found = []
    for folder, recursive in TARGETS:
        pattern = os.path.join(root, folder, "**", "*.cpp") if recursive else os.path.join(root, folder, "*.cpp")
        defined = collections.defaultdict(set)
        for path in sorted(glob.glob(pattern, recursive=recursive)):
            for name in local_functions(path, whole_file=folder.startswith("tests")):
                defined[name].add(os.path.relpath(path, root))
        for name, files in sorted(defined.items()):
            if len(files) > 1:
                found.append((folder, name, sorted(files)))
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
