"""unity_names.py: two test files of one room with a helper of the same name are found, as
are two library files with one in their unnamed namespaces; functions outside unnamed
namespaces (overloads a header declares) are not; and the project has none."""
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
SCRIPT = os.path.join(ROOT, "scripts", "unity_names.py")


def run(root):
    return subprocess.run([sys.executable, SCRIPT, str(root)], capture_output=True, text=True)


def write(root, name, text):
    path = root / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def test_same_named_file_local_helpers_are_found(tmp_path):
    write(tmp_path, "tests/nbv/a/test_a.cpp", "namespace {\nint helper(int x) {\n  return x;\n}\n}  // namespace\n")
    write(tmp_path, "tests/nbv/test_b.cpp", "double helper(double y, int z) {\n  return y;\n}\n")
    write(tmp_path, "nbv/x.cpp", "namespace saresgs {\nnamespace {\nvoid walk(int n) {\n}\n}  // namespace\n"
                                 "std::string toString(A a) {\n}\n}  // namespace saresgs\n")
    write(tmp_path, "nbv/y.cpp", "namespace saresgs {\nnamespace {\nbool walk(const Scene& s) {\n}\n}  // namespace\n"
                                 "std::string toString(B b) {\n}\n}  // namespace saresgs\n")
    r = run(tmp_path)
    assert r.returncode == 1, r.stdout + r.stderr
    assert "tests/nbv: helper is defined file-locally in tests/nbv/a/test_a.cpp, tests/nbv/test_b.cpp" in r.stdout
    assert "nbv: walk is defined file-locally in nbv/x.cpp, nbv/y.cpp" in r.stdout
    assert "toString" not in r.stdout
    assert "2 names" in r.stdout


def test_the_project_has_none():
    r = run(ROOT)
    assert r.returncode == 0, r.stdout + r.stderr


def test_geometry_is_checked_and_the_rasterizer_is_not(tmp_path):
    local = "namespace saresgs {\nnamespace {\nfloat rotationOf(int i) {\n}\n}  // namespace\n}  // namespace saresgs\n"
    write(tmp_path, "geometry/io/a.cpp", local)
    write(tmp_path, "geometry/synth/b.cpp", local)
    write(tmp_path, "splat/raster/c.cpp", local)  # the rasterizer's files are never batched
    write(tmp_path, "splat/train/d.cpp", local)
    r = run(tmp_path)
    assert r.returncode == 1, r.stdout + r.stderr
    assert "geometry: rotationOf is defined file-locally in geometry/io/a.cpp, geometry/synth/b.cpp" in r.stdout
    assert "splat: rotationOf" not in r.stdout
    assert "1 names" in r.stdout
    write(tmp_path, "splat/e.cpp", local)
    r = run(tmp_path)
    assert "splat: rotationOf is defined file-locally in splat/e.cpp, splat/train/d.cpp" in r.stdout


def test_one_line_definitions_and_the_fuzz_readers_are_checked(tmp_path):
    one_line = "namespace {\nbool isSpace(char c) { return c == ' '; }\n}  // namespace\n"
    write(tmp_path, "geometry/io/pfm.cpp", one_line)
    write(tmp_path, "nbv/run.cpp", one_line)
    write(tmp_path, "fuzz/targets.cmake", "set(SARESGS_FUZZ_READERS\n  geometry/io/pfm.cpp\n  nbv/run.cpp)\n")
    r = run(tmp_path)
    assert r.returncode == 1, r.stdout + r.stderr
    assert "fuzz readers: isSpace is defined file-locally in geometry/io/pfm.cpp, nbv/run.cpp" in r.stdout
    assert "1 names" in r.stdout  # geometry and nbv are targets of their own
    write(tmp_path, "geometry/x.cpp", "namespace {\nint isSpace(int c) {\n  return c;\n}\n}  // namespace\n")
    r = run(tmp_path)
    assert "geometry: isSpace is defined file-locally in geometry/io/pfm.cpp, geometry/x.cpp" in r.stdout
