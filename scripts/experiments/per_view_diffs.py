#!/usr/bin/env python3
"""Per-test-view final-fit PSNR of one method minus another, paired by seed, in an ablation folder.

Where a selector wins or loses, and which train views each chose.

  python3 scripts/experiments/per_view_diffs.py results/verdict2 unbalanced hybrid fisher
"""
import glob
import json
import sys
from collections import defaultdict


def runs(out, scene, method):
    r = {}
    for f in glob.glob(f"{out}/runs/{scene}__{method}__default__s*/results.json"):
        d = json.load(open(f))
        if d.get("final_fit"):
            r[d["seed"]] = d
    return r


def main():
    out, scene, a, b = sys.argv[1:5]
    ra, rb = runs(out, scene, a), runs(out, scene, b)
    seeds = sorted(set(ra) & set(rb))
    if not seeds:
        sys.exit(f"no seed with both {a} and {b} on {scene}")
    diff = defaultdict(list)
    for s in seeds:
        va = {v["name"]: v["psnr"] for v in ra[s]["final_fit"]["views"]}
        vb = {v["name"]: v["psnr"] for v in rb[s]["final_fit"]["views"]}
        for n in va:
            diff[n].append(va[n] - vb[n])
    print(f"{scene}: {a} - {b}, final-fit PSNR per test view, seeds {seeds}")
    total = []
    for n in sorted(diff):
        d = diff[n]
        total += d
        print(f"  {n}: mean {sum(d) / len(d):+.2f} dB  per seed " + " ".join(f"{x:+.2f}" for x in d))
    print(f"  all views: mean {sum(total) / len(total):+.3f} dB")
    for m, r in ((a, ra), (b, rb)):
        for s in seeds:
            print(f"  {m} s{s} chose " + " ".join(v[:4] for v in sorted(r[s]["selected_views"])))


if __name__ == "__main__":
    main()
