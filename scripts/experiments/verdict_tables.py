#!/usr/bin/env python3
"""Per-scene Markdown summary of a merged ablation folder: each method against fisher and fvs.

Final-fit PSNR (mean over seeds) of each method and its paired difference against fisher
and against fvs (mean, 95 % interval, seeds), from tables/results.csv and tables/paired.csv.

  python3 scripts/experiments/verdict_tables.py results/verdict2 [metric]   # metric: final_fit_psnr
"""
import csv
import sys
from collections import OrderedDict


def summary(out, metric="final_fit_psnr"):
    """The Markdown lines: per scene, each method's mean and its paired difference against fisher and fvs."""
    paired = list(csv.DictReader(open(f"{out}/tables/paired.csv")))
    results = list(csv.DictReader(open(f"{out}/tables/results.csv")))
    col = {"final_fit_psnr": "final-fit PSNR_mean", "plain_refit_psnr": "plain-refit PSNR_mean", "psnr": "PSNR_mean"}[metric]
    scenes = OrderedDict()
    for r in results:
        scenes.setdefault(r["scene"], []).append(r)

    def cell(scene, method, base):
        for p in paired:
            if p["scene"] == scene and p["method"] == method and p["baseline"] == base and p["metric"] == metric:
                lo, hi = p["ci_low"], p["ci_high"]
                ci = "" if lo == "undefined" else f" [{float(lo):+.2f}, {float(hi):+.2f}]"
                return f"{float(p['mean_diff']):+.2f}{ci} ({p['n']})"
        return ""
    lines = []
    for scene, rows in scenes.items():
        lines += [f"**{scene}**", "", f"| method | {metric} | vs fisher | vs fvs | seeds |", "|---|---:|---:|---:|---:|"]
        for r in rows:
            m = r["method"]  # with its variant, as paired.csv names it: "resgs (replay-fisher)"
            lines.append(f"| {m} | {r.get(col, '')} | {cell(scene, m, 'fisher')} | {cell(scene, m, 'fvs')} | {r['seeds']} |")
        lines.append("")
    return lines[:-1]


def main():
    out = sys.argv[1]
    metric = sys.argv[2] if len(sys.argv) > 2 else "final_fit_psnr"
    print("\n".join(summary(out, metric)))


if __name__ == "__main__":
    main()
