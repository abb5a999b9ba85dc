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
