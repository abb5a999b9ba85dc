#!/usr/bin/env python3
"""How near the views a run held are to the test views, against its final-fit PSNR.

For every run of an ablation output folder: the mean over the scene's test views of the
distance from the test camera's centre to the nearest held camera's centre (scene units)
and of the angle between their viewing directions (degrees), beside the run's final-fit
PSNR; per scene, the Pearson correlation of each with the PSNR over all runs. It needs no
training: the cameras come from the datasets (through the saresgs Python module).

  PYTHONPATH=build/python python3 scripts/experiments/nearest_view_analysis.py results/verdict2 GRID.json

Writes OUT/tables/nearest_view.md and prints it. Per scene it also measures how much of a
spread selection's result is its phase against the test views (phaseComparison), and compares fvs's held views
(seed 0) with greedy k-median on camera positions from the same initial views (the views that
minimise the mean distance of every train view to its nearest held one): its objective on the
train views and the test views' mean distance, for each. The test views are used here to
explain results, never by a selector.
"""
import glob
import json
import os
import sys

import numpy as np

import saresgs
from table_io import writeTable


def kmedianComparison(out, scene, ds, centres):
    """fvs's held views against greedy k-median on positions, from the same initial views."""
    f = f"{out}/runs/{scene}__fvs__default__s0/results.json"
    if not os.path.exists(f):
        return []
    r = json.load(open(f))
    train, test = np.array(ds.train), np.array(ds.test)
    fvs = np.array(r["selected_view_indices"])
    d = np.linalg.norm(centres[train][:, None] - centres[train][None], axis=2)
    held = [int(np.where(train == ds.names.index(n))[0][0]) for n in r["initial_views"]]
    nearest = d[:, held].min(1)
    while len(held) < len(fvs):
        gain = [np.minimum(nearest, d[:, c]).sum() if c not in held else np.inf for c in range(len(train))]
        held.append(int(np.argmin(gain)))
        nearest = np.minimum(nearest, d[:, held[-1]])
    kmed = train[held]

    def mean_nearest(views, sel):
        return np.linalg.norm(centres[views][:, None] - centres[sel][None], axis=2).min(1).mean()

    return ["", "| held views | mean distance, train views | mean distance, test views |", "|---|---:|---:|",
            f"| fvs (seed 0) | {mean_nearest(train, fvs):.3f} | {mean_nearest(test, fvs):.3f} |",
            f"| greedy k-median on positions | {mean_nearest(train, kmed):.3f} | {mean_nearest(test, kmed):.3f} |"]


def phaseComparison(out, scene, ds, centres, fit):
    """How much of a spread selection's score is its phase against the test views.

    Each held view of the run is moved k places along the capture path's train views (the
    same spacing, another phase; the path closes on itself when its ends are as near as two
    neighbouring views, else the moved views stop at its ends), and the test views' mean
    distance to the moved set is taken for k = -4..4. With the scene's fit of final-fit PSNR
    on that distance over all its runs, the spread of those distances is the spread of
    final-fit PSNR that phase alone would give. No training, no selector sees the test views.
    """
    train, test = np.array(ds.train), np.array(ds.test)
    steps = np.linalg.norm(np.diff(centres[train], axis=0), axis=1)
    closed = np.linalg.norm(centres[train[0]] - centres[train[-1]]) <= 2.0 * np.median(steps)
    pos = {int(v): i for i, v in enumerate(train)}
    lines = []
    for method in ("fvs", "adaptive"):
        files = sorted(glob.glob(f"{out}/runs/{scene}__{method}__default__s*/results.json"))
        rows = []
        for f in files:
            r = json.load(open(f))
            held = [pos[v] for v in r["selected_view_indices"] if v in pos]
            dists = []
            for k in range(-4, 5):
                moved = [(h + k) % len(train) if closed else min(max(h + k, 0), len(train) - 1) for h in held]
                sel = train[moved]
                dists.append(np.linalg.norm(centres[test][:, None] - centres[sel][None], axis=2).min(1).mean())
            rows.append(dists)
            if method == "fvs":
                break  # fvs holds the same views in every seed
        if not rows:
            continue
        d = np.array(rows)
        actual, shifted = d[:, 4].mean(), d.mean()
        rank = float((d < d[:, 4:5]).sum(axis=1).mean())
        lines.append(f"| {method} ({len(rows)} run{'s' if len(rows) > 1 else ''}) | {actual:.3f} | {shifted:.3f} | "
                     f"{d.min(axis=1).mean():.3f} - {d.max(axis=1).mean():.3f} | {rank:.1f} of 8 | "
                     f"{fit[0] * (actual - shifted):+.2f} |")
    if not lines:
        return []
    return ["", f"Phase ({'closed' if closed else 'open'} path): the held views moved k = -4..4 train views along it.",
            "", "| held views | test distance, as held | mean over k | range over k | shifts nearer than as held | "
            "PSNR from phase (fit) |", "|---|---:|---:|---:|---:|---:|"] + lines


def main():
    out, grid = sys.argv[1], sys.argv[2]
    datasets = {s["name"]: s["dataset"] for s in json.load(open(grid))["scenes"]}
    lines = ["# Nearest held view of each test view, against final-fit PSNR", "",
             "Mean over test views of the distance (scene units) and the angle (degrees) to the nearest held",
             "view; r: Pearson correlation with the final-fit PSNR over the scene's runs.", ""]
    for scene, path in datasets.items():
        files = sorted(glob.glob(f"{out}/runs/{scene}__*/results.json"))
        if not files:
            continue
        ds = saresgs.load_dataset(path)
        centres = np.array([c.center for c in ds.cameras])
        axes = np.array([c.R[2] for c in ds.cameras])  # the camera's z axis in world coordinates
        test = np.array(ds.test)
        rows = []
        for f in files:
            r = json.load(open(f))
            if not r.get("final_fit"):
                continue
            held = np.array(r["selected_view_indices"])
            dist = np.linalg.norm(centres[test][:, None] - centres[held][None], axis=2).min(1).mean()
            ang = np.degrees(np.arccos(np.clip(axes[test] @ axes[held].T, -1, 1))).min(1).mean()
            rows.append((os.path.basename(os.path.dirname(f)), r["final_fit"]["psnr"], dist, ang))
        a = np.array([x[1:] for x in rows])
        lines += [f"## {scene}", "", "| run | final-fit PSNR | distance | angle |", "|---|---:|---:|---:|"]
        lines += [f"| {n} | {p:.2f} | {d:.3f} | {g:.1f} |" for n, p, d, g in rows]
        if len(rows) > 2:
            c = np.corrcoef(a.T)
            lines += ["", f"r(PSNR, distance) = {c[0, 1]:+.2f}, r(PSNR, angle) = {c[0, 2]:+.2f} over {len(rows)} runs"]
        lines += kmedianComparison(out, scene, ds, centres)
        if len(rows) > 2:
            fit = np.polyfit(a[:, 1], a[:, 0], 1)  # PSNR = fit[0] distance + fit[1]
            lines += phaseComparison(out, scene, ds, centres, fit)
        lines.append("")
    writeTable(out, "nearest_view.md", lines)


if __name__ == "__main__":
    main()
