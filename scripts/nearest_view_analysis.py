#!/usr/bin/env python3
"""How near the views a run held are to the test views, against its final-fit PSNR.

For every run of an ablation output folder: the mean over the scene's test views of the
distance from the test camera's centre to the nearest held camera's centre (scene units)
and of the angle between their viewing directions (degrees), beside the run's final-fit
PSNR; per scene, the Pearson correlation of each with the PSNR over all runs. It needs no
training: the cameras come from the datasets (through the saresgs Python module).

  PYTHONPATH=build/python python3 scripts/nearest_view_analysis.py results/verdict2 GRID.json

Writes OUT/tables/nearest_view.md and prints it. Per scene it also compares fvs's held views
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
        lines.append("")
    text = "\n".join(lines)
    os.makedirs(f"{out}/tables", exist_ok=True)
    with open(f"{out}/tables/nearest_view.md", "w") as fh:
        fh.write(text + "\n")
    print(text)


if __name__ == "__main__":
    main()
