#!/usr/bin/env python3
"""Final-fit PSNR along the whole capture path, not only at its every-8th test views.

The verdict's test views are every 8th view of a capture path (on `object`, a separate
ring: views 100-149, which no selector can hold), so a selector whose held
views happen to fall next to them scores higher than one whose views fall between them,
whatever their spacing (scripts/experiments/nearest_view_analysis.py measures that phase). The final
fit trains on the held views alone, so every other view of the path is as unseen as a test
view. This script renders each run's final-fit model (final_fit.ply, kept in the run's
folder, not committed; scripts/experiments/refit_final_fit.sh rebuilds it byte for byte for runs of
864af66 or later) at every view of the path and compares two methods, paired by seed,
on the views neither of them held: all phases at once. It checks first that its PSNR at the
test views equals the run's results.json (the same render, to the printed digits).

  PYTHONPATH=build/python python3 scripts/experiments/path_psnr.py results/verdict2 GRID.json [A B] ...

A B: method pairs to compare (default: adaptive fvs, adaptive fisher, fisher fvs, sa-resgs fisher,
random fvs). Writes
OUT/tables/path_psnr.md and prints it, and draws OUT/plots/path_psnr.svg: per scene, each
compared method's PSNR at every path view (mean over the seeds all of them ran, each run's
own held views left out), the test views dashed, and under the axis the views each method
held (opacity: the fraction of seeds). No selector and no training sees these views.
"""
import glob
import json
import os
import sys

import numpy as np

import saresgs
from svg_plot import writeSvg
from table_io import interval95, writeTable


def viewPsnr(run, ds):
    """PSNR of the run's final-fit model at every view of the dataset, cached in the run folder."""
    ply = f"{run}/final_fit.ply"
    cache = f"{run}/path_psnr.json"
    bg = list(ds.background) if ds.background is not None else [0.0, 0.0, 0.0]  # the dataset's, as training's
    if os.path.exists(cache) and os.path.getmtime(cache) >= os.path.getmtime(ply):
        c = json.load(open(cache))
        if c.get("background") == bg and len(c["psnr"]) == len(ds.cameras):
            return np.array(c["psnr"])
    g = saresgs.Gaussians.read_ply(ply)
    out = []
    for i in range(len(ds.cameras)):
        rgb, _, _ = saresgs.render(g, ds.camera(i), background=bg)
        out.append(saresgs.psnr(rgb, ds.image_float(i)))
    with open(cache + ".tmp", "w") as fh:
        json.dump({"background": bg, "psnr": out}, fh)
    os.replace(cache + ".tmp", cache)
    return np.array(out)


DEFAULT_PAIRS = [("adaptive", "fvs"), ("adaptive", "fisher"), ("fisher", "fvs"), ("sa-resgs", "fisher"),
                 ("random", "fvs")]


def main():
    out, grid = sys.argv[1], sys.argv[2]
    rest = sys.argv[3:]
    pairs = [(rest[i], rest[i + 1]) for i in range(0, len(rest) - 1, 2)] or DEFAULT_PAIRS
    # The figure: the recommended selector and the two baselines, unless pairs are named.
    figure = [m for pair in pairs for m in pair] if rest else ["fisher", "fvs", "adaptive"]
    scenes = {s["name"]: s["dataset"] for s in json.load(open(grid))["scenes"]}
    lines = ["# Final-fit PSNR along the whole capture path", "",
             "Each run's final-fit model rendered at every view of the path. *test*: the test views, every 8th",
             "view of the path (`object`: its separate test ring, views 100-149; the verdict's metric); *path*: the views neither method held (unseen by both final fits, every",
             "phase of the path). Paired by seed: mean difference [95 % Student-t interval] (seeds). Only runs",
             "whose final_fit.ply is in their folder count. From `scripts/experiments/path_psnr.py`.", "",
             "| scene | A | B | seeds | A - B, test views | A - B, path views | path views per seed |",
             "|---|---|---|---:|---:|---:|---:|"]
    panels = []
    for scene, path in scenes.items():
        ds = saresgs.load_dataset(path)
        test = sorted(int(i) for i in ds.test)
        runs = {}
        for f in sorted(glob.glob(f"{out}/runs/{scene}__*__default__s*/final_fit.ply")):
            run = os.path.dirname(f)
            res = f"{run}/results.json"
            if not os.path.exists(res):
                continue
            r = json.load(open(res))
            _, method, _, seed = os.path.basename(run).split("__")
            p = viewPsnr(run, ds)
            at_test = float(np.mean(p[test]))
            if abs(at_test - r["final_fit"]["psnr"]) > 1e-3:
                sys.exit(f"path_psnr: {run}: PSNR at the test views {at_test:.4f} is not results.json's "
                         f"{r['final_fit']['psnr']:.4f}: this model or render is not the run's")
            runs[(method, int(seed[1:]))] = (p, set(r["selected_view_indices"]), at_test)
        for a, b in pairs:
            seeds = sorted(s for (m, s) in runs if m == a and (b, s) in runs)
            if not seeds:
                continue
            d_test, d_path, n_path = [], [], []
            for s in seeds:
                pa, ha, ta = runs[(a, s)]
                pb, hb, tb = runs[(b, s)]
                views = [v for v in range(len(pa)) if v not in ha and v not in hb]
                d_test.append(ta - tb)
                d_path.append(float(np.mean(pa[views]) - np.mean(pb[views])))
                n_path.append(len(views))
            t, p = interval95(d_test), interval95(d_path)
            lines.append(f"| {scene} | {a} | {b} | {','.join(map(str, seeds))} | {t[0]:+.2f} [{t[1]:+.2f}, {t[2]:+.2f}] | "
                         f"{p[0]:+.2f} [{p[1]:+.2f}, {p[2]:+.2f}] | {min(n_path)}-{max(n_path)} |")
        panel = pathPanel(scene, runs, figure, test)
        if panel:
            panels.append(panel)
    writeTable(out, "path_psnr.md", lines)
    if panels:
        writeSvg(f"{out}/plots/path_psnr.svg", panels,
                 "Final-fit PSNR at every view of the capture path (scripts/experiments/path_psnr.py); dashed: the test views")
        print(f"path_psnr: drew {out}/plots/path_psnr.svg")


def pathPanel(scene, runs, methods, test):
    """The figure's panel for one scene: the methods (first appearance order) over the seeds
    all of them ran; None when no seed is shared."""
    methods = [m for k, m in enumerate(methods) if m not in methods[:k] and any(r == m for r, _ in runs)]
    seeds = sorted(set.intersection(*[{s for (r, s) in runs if r == m} for m in methods])) if methods else []
    if not seeds:
        return None
    n = len(runs[(methods[0], seeds[0])][0])
    series, strips = [], []
    for m in methods:
        ys, held = [], {}
        for v in range(n):
            unseen = [runs[(m, s)][0][v] for s in seeds if v not in runs[(m, s)][1]]
            ys.append(float(np.mean(unseen)) if unseen else float("nan"))
            k = sum(v in runs[(m, s)][1] for s in seeds)
            if k:
                held[v] = k / len(seeds)
        path_mean = float(np.nanmean([y for v, y in enumerate(ys) if v not in test]))
        series.append((f"{m} {path_mean:.2f}", ys))
        strips.append((m, held))
    return {"title": f"{scene}: seeds {','.join(map(str, seeds))} (legend: mean over the views that are not test views)",
            "xlabel": "view along the capture path; under the axis: the views each method held (opacity: share of seeds)", "ylabel": "final-fit PSNR (dB)", "n": n,
            "series": series, "marks": test, "strips": strips}


if __name__ == "__main__":
    main()
