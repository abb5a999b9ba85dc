#!/usr/bin/env python3
"""A view selector written in Python, run against FisherRF on two scenes and two seeds.

    PYTHONPATH=build/python python3 examples/custom_selector.py [--work DIR]

The selector (`spread_fisher`, below) takes FisherRF's information gain and discounts
candidates close to a view already held (it multiplies the two scores), the redundancy FisherRF ignores. Each (scene,
seed) runs both selectors from the same initial model, trainer seed and test views, and
the table pairs their final-fit PSNR. Small scenes and a short schedule, so that the whole
example runs in a few minutes on two cores: a demonstration of the API, not a verdict
(results/ holds those).
"""
import argparse
import pathlib

import numpy as np

import saresgs


def spread_fisher(ctx):
    """FisherRF's gain times the distance to the nearest held camera (both scaled to 1)."""
    info = np.asarray(ctx.fisher_scores())  # as the fisher method scores them
    dist = np.asarray(ctx.fvs_scores())     # as the fvs method scores them
    score = info / max(info.max(), 1e-30) * (dist / max(dist.max(), 1e-30))
    return ctx.candidates[int(np.argmax(score))], score.tolist()


# Two-sided 95 % Student t quantiles by degrees of freedom.
T95 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", default="/tmp/saresgs_example", help="where the scenes are written")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    args = ap.parse_args()
    run_opts = dict(preset="quick", max_views=12, interval=20, min_iterations=600, final_iterations=400)
    print(f"{'scene':<12} {'seed':>4} {'fisher':>8} {'spread':>8} {'diff':>7}  views in common")
    for layout in ("room360", "unbalanced"):
        folder = pathlib.Path(args.work) / layout
        ds = (saresgs.load_dataset(str(folder)) if (folder / "manifest.json").exists()
              else saresgs.make_scene(layout, str(folder), width=80, height=60, seed=0, views=40))
        diffs = []
        for seed in args.seeds:
            fisher = saresgs.ActiveRun(ds, method="fisher", seed=seed, **run_opts).run()
            mine = saresgs.ActiveRun(ds, selector=spread_fisher, seed=seed, **run_opts).run()
            a, b = fisher["final_fit"]["psnr"], mine["final_fit"]["psnr"]
            diffs.append(b - a)
            common = len(set(fisher["selected_view_indices"]) & set(mine["selected_view_indices"]))
            print(f"{layout:<12} {seed:>4} {a:8.2f} {b:8.2f} {b - a:+7.2f}  {common} of {len(mine['selected_view_indices'])}",
                  flush=True)
        d = np.asarray(diffs)
        half = T95.get(len(d) - 1, 1.96) * d.std(ddof=1) / np.sqrt(len(d)) if len(d) > 1 else float("nan")
        print(f"{layout:<12} {'mean':>4} {'':>8} {'':>8} {d.mean():+7.2f}  95% CI [{d.mean() - half:+.2f}, {d.mean() + half:+.2f}]")


if __name__ == "__main__":
    main()
