#!/usr/bin/env python3
"""Final-fit PSNR per hash size, paired by seed against hash:auto (the paper's hash-size claim).

The PSNR half of the claim: each hash size of a grid like results/grid_hash.json, paired by
seed against its `default` variant (hash:auto), with each size's table and load as the runs
recorded them (results.json's prefilter_regime).

  python3 scripts/experiments/hash_size_table.py results/verdict2 results/grid_hash.json

Writes OUT/tables/hash_size_psnr.md and prints it. Only finished runs count; a size
missing a seed that its reference has is paired over the seeds both have.
"""
import json
import os
import sys

from table_io import interval95, writeTable


def load(path):
    try:
        return json.load(open(path))
    except (OSError, ValueError):
        return None


def main():
    out, grid_path = sys.argv[1], sys.argv[2]
    grid = json.load(open(grid_path))
    variants = [v["name"] for v in grid["variants"]]
    lines = ["# Final-fit PSNR per hash size, paired against hash:auto", "",
             f"From `{os.path.basename(grid_path)}` ({', '.join(grid['methods'])}); `scripts/experiments/hash_size_table.py`. "
             "Differences: this size minus the `default` variant (hash:auto) on the same seed; "
             "mean [95 % Student-t interval] over seeds, and each seed's.", "",
             "| scene | variant | encoding | load | seeds | final-fit PSNR | minus hash:auto | per seed |",
             "|---|---|---|---:|---:|---:|---:|---|"]
    for scene in [s["name"] for s in grid["scenes"]]:
        for method in grid["methods"]:
            ref = {s: load(f"{out}/runs/{scene}__{method}__default__s{s}/results.json") for s in grid["seeds"]}
            for v in variants:
                runs = ref if v == "default" else {
                    s: load(f"{out}/runs/{scene}__{method}__{v}__s{s}/results.json") for s in grid["seeds"]}
                runs = {s: r for s, r in runs.items() if r and r.get("final_fit")}
                if not runs:
                    continue
                regime = next(iter(runs.values())).get("prefilter_regime", {})
                load_factor = regime.get("load_factor")
                psnr = [r["final_fit"]["psnr"] for r in runs.values()]
                diffs = [runs[s]["final_fit"]["psnr"] - ref[s]["final_fit"]["psnr"]
                         for s in sorted(runs) if ref.get(s) and ref[s].get("final_fit")]
                cell = ""
                if diffs and v != "default":
                    m, lo, hi = interval95(diffs)
                    cell = f"{m:+.2f}" if len(diffs) == 1 else f"{m:+.2f} [{lo:+.2f}, {hi:+.2f}]"
                lines.append(f"| {scene} | {v} | {regime.get('encoding', '')} | "
                             f"{'' if load_factor is None else f'{load_factor:.2f}'} | {len(runs)} | "
                             f"{sum(psnr) / len(psnr):.2f} | {cell} | "
                             f"{' '.join(f'{d:+.2f}' for d in diffs) if v != 'default' else ''} |")
    writeTable(out, "hash_size_psnr.md", lines)


if __name__ == "__main__":
    main()
