#!/usr/bin/env python3
"""Pair the residual refits of scripts/experiments/residual_refit.sh against the baselines' final fits.

    python3 scripts/experiments/residual_refit_table.py OUTDIR RUNS_DIR

OUTDIR holds OUTDIR/SCENE__METHOD__VARIANT__sN/refit.json (a residual refit of that run's
views); RUNS_DIR the grid's runs (results/verdict2/runs). For each scene and method it pairs,
seed by seed, the residual refit against the run's own plain final fit (training alone, same
views) and against fisher's and fvs's final fits (the method with residual training against
the baselines as they are), and writes OUTDIR/tables/paired.md: mean difference, 95 %
Student-t interval over seeds, and the seeds.
"""
import json
import os
import sys

from table_io import interval95, writeTable


def psnr_of(path, key):
    if not os.path.exists(path):
        return None
    r = json.load(open(path))
    return r[key]["psnr"] if key else r["psnr"]


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    outdir, runs = sys.argv[1:]
    groups = {}
    for job in sorted(os.listdir(outdir)):
        parts = job.split("__")
        if len(parts) != 4 or not os.path.exists(os.path.join(outdir, job, "refit.json")):
            continue
        scene, method, variant, seed = parts
        groups.setdefault((scene, method, variant), []).append(seed)
    if not groups:
        sys.exit(f"residual_refit_table: no refits in {outdir}")
    lines = ["### Residual refits of a method's views against final fits, paired by seed (mean, 95 % "
             "Student-t interval, seeds); from scripts/experiments/residual_refit_table.py", "",
             "| scene | method (residual refit) | against | mean_diff | ci_low | ci_high | n | per seed |",
             "|---|---|---|---:|---:|---:|---:|---|"]
    for (scene, method, variant), seeds in sorted(groups.items()):
        name = method if variant == "default" else f"{method} ({variant})"
        for against, job_of in (("own plain final fit", lambda s: f"{scene}__{method}__{variant}__{s}"),
                                ("fisher", lambda s: f"{scene}__fisher__default__{s}"),
                                ("fvs", lambda s: f"{scene}__fvs__default__{s}")):
            diffs = []
            for s in seeds:
                mine = psnr_of(os.path.join(outdir, f"{scene}__{method}__{variant}__{s}", "refit.json"), None)
                theirs = psnr_of(os.path.join(runs, job_of(s), "results.json"), "final_fit")
                if mine is not None and theirs is not None:
                    diffs.append(mine - theirs)
            if not diffs:
                continue
            m, lo, hi = interval95(diffs)
            per = ", ".join(f"{d:+.2f}" for d in diffs)
            lo_s, hi_s = ("n/a", "n/a") if len(diffs) < 2 else (f"{lo:+.3f}", f"{hi:+.3f}")
            lines.append(f"| {scene} | {name} | {against} | {m:+.3f} | {lo_s} | {hi_s} | {len(diffs)} | {per} |")
    writeTable(outdir, "paired.md", lines)


if __name__ == "__main__":
    main()
