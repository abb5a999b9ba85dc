"""include_circles.py: finds a circle of units on a made-up tree (through a source file, as
a header and its .cpp are one unit), names none where the includes only go one way, and
the project's own tree has none."""
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
SCRIPT = os.path.join(ROOT, "scripts", "include_circles.py")


def run(root):
    return subprocess.run([sys.executable, SCRIPT, str(root)], capture_output=True, text=True)


def make_tree(tmp_path, spec):
    """spec: one line per file, "FILE: INCLUDED FILES" (quoted includes; <vector> as is)."""
    for line in spec.strip().splitlines():
        name, includes = line.split(":")
        path = tmp_path / name.strip()
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("".join(f"#include {i if i.startswith('<') else chr(34) + i + chr(34)}\n"
                                for i in includes.split()))
    subprocess.run(["git", "init", "-q", str(tmp_path)], check=True)
    subprocess.run(["git", "-C", str(tmp_path), "add", "."], check=True)


def test_a_circle_through_a_source_file_is_found(tmp_path):
    make_tree(tmp_path, """
        a/x.h: a/y.h
        a/y.h:
        a/y.cpp: a/y.h a/z.h
        a/z.h: a/x.h
        b/w.h: <vector>
    """)
    r = run(tmp_path)
    assert r.returncode == 1, r.stdout + r.stderr
    assert "circle: a/x, a/y, a/z" in r.stdout
    assert "a/y -> a/z" in r.stdout
    assert "b/w" not in r.stdout.split("units")[0]


def test_includes_one_way_are_no_circle(tmp_path):
    make_tree(tmp_path, """
        a/x.h: a/y.h
        a/x.cpp: a/x.h a/z.h
        a/y.h: a/z.h
        a/z.h:
    """)
    r = run(tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "3 units, 0 circles" in r.stdout


def test_the_project_has_no_circle():
    r = run(ROOT)
    assert r.returncode == 0, r.stdout + r.stderr
