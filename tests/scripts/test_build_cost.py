"""build_cost.py: steps summed by room from Ninja's logs; the fuzz project's own steps
replace the one step of the main build that ran them, and a step that wrote several outputs
counts once."""
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "..", "..", "scripts", "build_cost.py")


def log(path, rows):
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = ["# ninja log v5"] + [f"{s}\t{e}\t0\t{out}\t{h}" for s, e, out, h in rows]
    path.write_text("\n".join(lines) + "\n")


def run(build):
    return subprocess.run([sys.executable, SCRIPT, str(build)], capture_output=True, text=True, check=True).stdout


def test_rooms_the_fuzz_projects_own_steps_and_a_step_counted_once(tmp_path):
    log(tmp_path / ".ninja_log", [
        (0, 4000, "geometry/CMakeFiles/saresgs_geometry.dir/Unity/unity_0_cxx.cxx.o", "a"),
        (0, 2000, "splat/CMakeFiles/saresgs_splat.dir/raster/pair.cpp.o", "b"),
        (2000, 3000, "tests/CMakeFiles/test_nbv.dir/nbv/test_x.cpp.o", "c"),
        (4000, 9000, "saresgs_fuzz-prefix/src/saresgs_fuzz-stamp/saresgs_fuzz-build-byproduct", "d"),
        (4000, 9000, "saresgs_fuzz-prefix/src/saresgs_fuzz-stamp/saresgs_fuzz-build", "d"),  # the same step
        (9000, 9500, "apps/saresgs", "e"),
    ])
    out = run(tmp_path)
    assert "| fuzz targets (clang, their own project) | 5 |" in out  # no log of its own: the one step
    assert "Build steps: 5, wall 10 s, steps summed 12 s" in out
    assert "| geometry | 4 |" in out and "| splat | 2 |" in out and "| tests/nbv | 1 |" in out
    assert "| 4.0 | saresgs_geometry: Unity/unity_0_cxx |" in out
    log(tmp_path / "fuzz" / ".ninja_log", [
        (0, 3000, "CMakeFiles/fuzz_readers.dir/Unity/unity_0_cxx.cxx.o", "f"),
        (0, 3000, "CMakeFiles/fuzz_readers.dir/Unity/unity_1_cxx.cxx.o", "g"),
        (0, 2500, "CMakeFiles/fuzz_pfm.dir/fuzz_pfm.cpp.o", "h"),
    ])
    out = run(tmp_path)
    assert "| fuzz targets (clang, their own project) | 8 |" in out  # 3 + 3 + 2.5, not the step's 5
    assert "Build steps: 7, wall 10 s, steps summed 16 s" in out
    assert "| 3.0 | fuzz: fuzz_readers: Unity/unity_0_cxx |" in out
    assert "| 2.5 | fuzz: fuzz_pfm.cpp |" in out
