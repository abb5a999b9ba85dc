"""verdict3_tables.py's statistics and tables on runs made up here: the two-level bootstrap
counts the variance of scenes, a pair is judged over the views neither run held, the better
baseline is chosen per capture type, and --check fails on a stale table."""
import importlib.util
import json
import os
import random
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "..", "..", "scripts", "experiments", "verdict3_tables.py")
spec = importlib.util.spec_from_file_location("verdict3_tables", SCRIPT)
v3 = importlib.util.module_from_spec(spec)
spec.loader.exec_module(v3)


def test_a_constant_difference_has_a_point_interval():
    m, lo, hi = v3.two_level_bootstrap({"a": [0.3, 0.3], "b": [0.3, 0.3, 0.3]}, random.Random(1))
    assert m == pytest.approx(0.3) and lo == pytest.approx(0.3) and hi == pytest.approx(0.3)


def test_one_scene_one_seed_has_no_interval():
    m, lo, hi = v3.two_level_bootstrap({"a": [0.5]}, random.Random(1))
    assert m == 0.5 and lo != lo and hi != hi


def test_the_variance_of_scenes_widens_the_interval():
    # Seeds agree within each scene, scenes disagree: a seed-only interval would be tight,
    # the two-level one spans the scenes' spread.
    by_scene = {"a": [1.0, 1.01, 0.99], "b": [-1.0, -1.01, -0.99], "c": [0.1, 0.11, 0.09]}
    m, lo, hi = v3.two_level_bootstrap(by_scene, random.Random(1))
    assert m == pytest.approx(0.1 / 3 + 0.0, abs=1e-9)
    assert lo < -0.5 and hi > 0.5
    # The same scenes' own seed spread alone is small.
    _, lo1, hi1 = v3.two_level_bootstrap({"a": by_scene["a"]}, random.Random(1))
    assert hi1 - lo1 < 0.05


def run(views, held, psnrs, test_psnr=25.0, initial=()):
    return {"initial_views": list(initial), "selected_views": held, "final_fit": {"psnr": test_psnr, "ssim": 0.9,
            "path": [{"name": v, "psnr": p} for v, p in zip(views, psnrs)]}}


def write_grid(tmp, methods, jobs):
    grid = {"scenes": [{"name": "o-s2", "layout": "object"}, {"name": "o-s3", "layout": "object"}],
            "methods": methods, "seeds": [0, 1]}
    for job, r in jobs.items():
        os.makedirs(os.path.join(tmp, "runs", job))
        with open(os.path.join(tmp, "runs", job, "results.json"), "w") as fh:
            json.dump(r, fh)
    with open(os.path.join(tmp, "grid.json"), "w") as fh:
        json.dump(grid, fh)
    return grid


def test_pairs_are_judged_over_the_views_neither_run_held(tmp_path):
    views = ["i", "a", "b", "c", "d"]
    jobs = {}
    for s in ("o-s2", "o-s3"):
        for seed in (0, 1):
            # Every run starts from the initial view i; fvs then holds a, fisher b: over c
            # and d fvs is 1 dB ahead; on its own held view (and i) fisher would look 10 dB
            # better, which must not count.
            jobs[f"{s}__fvs__default__s{seed}"] = run(views, ["a"], [20, 40, 20, 21, 21], initial=["i"])
            jobs[f"{s}__fisher__default__s{seed}"] = run(views, ["b"], [30, 20, 30, 20, 20], initial=["i"])
            jobs[f"{s}__random__default__s{seed}"] = run(views, ["a"], [40, 40, 19, 19, 19], initial=["i"])
            jobs[f"{s}__oracle__default__s{seed}"] = run(views, ["a"], [40, 40, 23, 23, 23], initial=["i"])
    grid = write_grid(str(tmp_path), ["random", "fisher", "fvs", "oracle"], jobs)
    md, csv_text = v3.tables(grid, str(tmp_path))
    # fvs along its unheld path: (20+21+21)/3; fisher: (20+20+20)/3: fvs is the better baseline.
    assert "Against the better baseline, **fvs**" in md
    methods, paired = md.split("Against the better baseline")
    # Paired over c and d: fisher 20 against fvs 21, in both scenes and seeds.
    row = [l for l in paired.splitlines() if l.startswith("| fisher | 4 | 2 |")][0]
    assert "| -1.000 | -1.000 | -1.000 |" in row and "below, clear of 0" in row
    # The oracle's share: random 19, oracle 23, fvs (20+21+21)/3 -> 0.42; the longest stretch
    # of path views fvs held none of: b, c, d.
    assert [l for l in methods.splitlines() if l.startswith("| fvs | 4 |")][0].endswith("| 0.42 | 3.0 |")
    assert "(16 finished runs, 0 missing)" in md


def test_one_scene_gets_no_verdict_across_scenes(tmp_path):
    views = ["a", "b", "c"]
    jobs = {f"o-s2__{m}__default__s{seed}": run(views, ["a"], [30, 20 + (m == "fvs"), 20])
            for m in ("fisher", "fvs") for seed in (0, 1)}
    grid = write_grid(str(tmp_path), ["fisher", "fvs"], jobs)
    md, _ = v3.tables(grid, str(tmp_path))
    row = [l for l in md.split("Against the better baseline")[1].splitlines() if l.startswith("| fisher |")][0]
    assert "one scene: no verdict across scenes" in row and "clear of 0" not in row


def test_check_fails_on_a_stale_table_and_passes_on_a_fresh_one(tmp_path):
    views = ["a", "b"]
    jobs = {f"{s}__{m}__default__s{seed}": run(views, ["a"], [30, 20 + seed])
            for s in ("o-s2", "o-s3") for m in ("fisher", "fvs") for seed in (0, 1)}
    write_grid(str(tmp_path), ["fisher", "fvs"], jobs)
    cmd = [sys.executable, SCRIPT, "--grid", str(tmp_path / "grid.json"), "--out", str(tmp_path)]
    assert subprocess.run(cmd + ["--check"], capture_output=True).returncode == 1  # nothing written yet
    assert subprocess.run(cmd, capture_output=True).returncode == 0
    assert subprocess.run(cmd + ["--check"], capture_output=True).returncode == 0
    # One run's number changes: the committed table is stale.
    p = tmp_path / "runs" / "o-s2__fvs__default__s0" / "results.json"
    r = json.loads(p.read_text())
    r["final_fit"]["path"][1]["psnr"] += 0.5
    p.write_text(json.dumps(r))
    out = subprocess.run(cmd + ["--check"], capture_output=True, text=True)
    assert out.returncode == 1 and "stale" in out.stdout


def test_scene_by_scene_shows_whose_deficit_it_is(tmp_path):
    # fisher trails fvs by 2 dB in o-s2 and by nothing in o-s3: the capture type's mean is
    # -1, the scene-by-scene row says where it comes from.
    views = ["i", "a", "b", "c"]
    jobs = {}
    for seed in (0, 1):
        for s, gap in (("o-s2", 2.0), ("o-s3", 0.0)):
            jobs[f"{s}__fvs__default__s{seed}"] = run(views, ["a"], [30, 30, 22, 22], initial=["i"])
            jobs[f"{s}__fisher__default__s{seed}"] = run(views, ["a"], [30, 30, 22 - gap, 22 - gap], initial=["i"])
    grid = write_grid(str(tmp_path), ["fisher", "fvs"], jobs)
    md, _ = v3.tables(grid, str(tmp_path))
    by_scene = md.split("Scene by scene")[1]
    assert "| fvs (dB) | 22.000 | 22.000 |" in by_scene
    assert "| fisher | -2.000 | +0.000 |" in by_scene


def test_the_bar_names_the_capture_types_that_fail_it(tmp_path):
    # Two capture types, two scenes each: adaptive 1 dB above the better baseline everywhere
    # on "object"; on "room" 0.5 dB below in one scene and level in the other.
    grid = {"scenes": [{"name": "o-s2", "layout": "object"}, {"name": "o-s3", "layout": "object"},
                       {"name": "r-s2", "layout": "room"}, {"name": "r-s3", "layout": "room"}],
            "methods": ["fisher", "fvs", "adaptive"], "seeds": [0, 1]}
    views = ["i", "a", "b", "c"]
    for s in ("o-s2", "o-s3", "r-s2", "r-s3"):
        lift = 1.0 if s.startswith("o") else (-0.5 if s == "r-s2" else 0.0)
        for seed in (0, 1):
            for m, p in (("fvs", 25.0), ("fisher", 24.0), ("adaptive", 25.0 + lift)):
                d = tmp_path / "runs" / f"{s}__{m}__default__s{seed}"
                d.mkdir(parents=True)
                (d / "results.json").write_text(json.dumps(run(views, ["a"], [30, 30, p, p], initial=["i"])))
    md, _ = v3.tables(grid, str(tmp_path))
    bar = md.split("## The default and the new selector against the bar")[1]
    assert "| adaptive | object | 4 | 2 | 1.000 | 1.000 | 1.000 | yes | yes |" in bar
    assert "| adaptive | room | 4 | 2 | -0.250 | -0.500 | 0.000 | no | no |" in bar
    line = [l for l in bar.splitlines() if l.startswith("- **adaptive**")][0]
    assert "above -0.1 on 1 of 2 capture types (not on room)" in line and "clear of zero on 1 (object)" in line
    assert line.endswith("the bar is not met on this grid's 2 capture types.")


def test_the_per_view_figure_leaves_out_the_views_either_run_held(tmp_path):
    views = ["i", "a", "b", "c"]
    jobs = {}
    for s in ("o-s2", "o-s3"):
        for seed in (0, 1):
            jobs[f"{s}__fvs__default__s{seed}"] = run(views, ["a"], [30, 30, 20, 20], initial=["i"])
            # adaptive holds b in seed 0 only: b's difference is seed 1's alone.
            held_b = ["b"] if seed == 0 else ["c"]
            jobs[f"{s}__adaptive__default__s{seed}"] = run(views, held_b, [30, 31, 21 + seed, 22], initial=["i"])
    for r in jobs.values():
        r["views"] = [{"name": "c", "psnr": 0.0}]  # the test views
    grid = write_grid(str(tmp_path), ["fvs", "adaptive"], jobs)
    figures = {}
    v3.tables(grid, str(tmp_path), figures=figures)
    panel = v3.per_view_panel("o-s2", {(s, m, seed): r for (s, m, seed), r in
                                       ((tuple(k.split("__")[0:1]) + (k.split("__")[1], int(k[-1])), v)
                                        for k, v in jobs.items())}, "fvs", ["adaptive"], [0, 1])
    (label, ys), = panel["series"]
    # i and a: held by both runs -> gaps; b: seed 1 only (22 - 20); c: seed 0 only (22 - 20).
    assert label == "adaptive" and ys[0] != ys[0] and ys[1] != ys[1] and ys[2] == 2.0 and ys[3] == 2.0
    assert panel["marks"] == [3]
    assert dict(panel["strips"])["adaptive"] == {0: 1.0, 2: 0.5, 3: 0.5}
    assert set(figures) == {"object"} and figures["object"].startswith("<svg") and "o-s3" in figures["object"]


def test_the_longest_unheld_stretch_counts_the_path_ends_and_no_wrap():
    views = [f"v{i}" for i in range(10)]
    # Held: v0 (initial), v3, v4: the stretches are v1-v2 (2) and v5-v9 (5).
    assert v3.longest_unheld_stretch(run(views, ["v3", "v4"], [20] * 10, initial=["v0"])) == 5
    # Held v9 only: v0..v8 is one stretch of 9 (no wrap to v9's far side).
    assert v3.longest_unheld_stretch(run(views, ["v9"], [20] * 10)) == 9
    assert v3.longest_unheld_stretch(run(views, views, [20] * 10)) == 0


def test_path_variance_against_adaptive_is_paired_over_views_neither_held(tmp_path):
    # path-variance 0.4 dB above adaptive in every scene and seed on the views both left out;
    # on the view only adaptive held (b), path-variance's 10 dB more must not count.
    views = ["i", "a", "b", "c"]
    jobs = {}
    for s in ("o-s2", "o-s3"):
        for seed in (0, 1):
            jobs[f"{s}__fvs__default__s{seed}"] = run(views, ["a"], [30, 30, 25, 25], initial=["i"])
            jobs[f"{s}__adaptive__default__s{seed}"] = run(views, ["b"], [30, 25, 30, 25], initial=["i"])
            jobs[f"{s}__path-variance__default__s{seed}"] = run(views, ["a"], [30, 30, 40, 25.4], initial=["i"])
    grid = write_grid(str(tmp_path), ["fvs", "adaptive", "path-variance"], jobs)
    md, _ = v3.tables(grid, str(tmp_path))
    head = md.split("## path-variance against adaptive")[1]
    assert "| object | 4 | 2 | 0.400 | 0.400 | 0.400 | +0.40, +0.40 |" in head
