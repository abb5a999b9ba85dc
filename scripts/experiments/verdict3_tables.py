#!/usr/bin/env python3
"""Verdict 3's tables (issue 49): every selector judged across scenes by its final fit's along-path PSNR.

From the committed runs alone. Reads a grid config (results/grid_verdict3.json: scenes with
their capture type, "layout", methods, trainer seeds) and each finished job's results.json
under OUT/runs/, and writes OUT/tables/verdict3.md (and .csv). With --check it writes nothing
and fails (exit 1) when the committed tables differ from what the runs give: the test command
runs it that way, so a stale number cannot stay. It reads the runs git tracks then (a grid
still running leaves others on disk); commit new runs with the tables they give.

Measures, all of the final fit (the method's own training on its chosen views):
- along the path: the mean PSNR over every view of the dataset that the run did not hold
  (final_fit.path); between two methods of the same scene and trainer seed, over the views
  neither held;
- the held-out test views' PSNR and SSIM (final_fit.psnr, .ssim).
Against the better baseline of each capture type (whichever of fisher and fvs has the higher
mean along-path PSNR over the capture type's runs), each method's paired difference per
(scene, seed), with a two-level bootstrap interval: scenes drawn with replacement, then seeds
within each drawn scene, the statistic the mean of the scene means; 10000 draws from a fixed
generator, the 2.5 and 97.5 percentiles. A deterministic selector's luck with one scene thus
counts as the variance of scenes. The oracle's share: (method - random) / (oracle - random)
of the mean along-path PSNR. The longest unheld stretch: the mean over runs of the most
consecutive path views a run held none of, how much of the path a selection left unseen.

Beside each capture type's tables: every method's difference scene by scene (is a deficit one
scene's or all of them?) and a figure, OUT/plots/NAME_per_view_CAPTURE.svg, of the judged
selectors' and the oracle's difference view by view along each scene's path. Last, the judged
selectors (JUDGED: the default and the selector issue 49 adds) against the issue's bar: a low
end above -0.1 dB on every capture type, clear of zero on at least two; and the two judged
selectors against each other, paired the same way.
"""
import argparse
import csv
import io
import json
import os
import random
import subprocess
import sys

DRAWS = 10000
BASELINES = ("fisher", "fvs")
# The selectors held to issue 49's bar: `saresgs active`'s default and the selector aimed at
# the path's views.
JUDGED = ("adaptive", "path-variance")
BAR_LOW = -0.1  # every capture type's low end above this
BAR_CLEAR = 2  # capture types clear of zero, at least

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from svg_plot import svgText  # noqa: E402  (beside this script)


def labels(grid):
    """[(label, method, variant)] in the grid's order: a method's default variant is named
    by the method, any other as "method (variant)"."""
    out = []
    for m in grid["methods"]:
        for v in grid.get("variants", [{"name": "default"}]):
            if v.get("methods") and m not in v["methods"]:
                continue
            out.append((m if v["name"] == "default" else f"{m} ({v['name']})", m, v["name"]))
    return out


def tracked_files(out):
    """The results.json files under OUT/runs that git tracks (the committed runs), or None
    outside a git work tree or in a folder git ignores (a build folder: nothing there is
    committed, so what is on disk counts)."""
    try:
        if subprocess.run(["git", "check-ignore", "-q", "--", out], capture_output=True).returncode == 0:
            return None
        listed = subprocess.run(["git", "ls-files", "--", os.path.join(out, "runs")], capture_output=True, text=True,
                                check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    return {os.path.normpath(p) for p in listed.splitlines() if p.endswith("results.json")}


def load_runs(grid, out, only=None):
    """{(layout, scene, label, seed): results.json} of the finished jobs, and the list of job
    ids still missing. `only`: a set of the files to read (the committed runs); others count
    as missing."""
    runs, missing = {}, []
    for sc in grid["scenes"]:
        for label, m, variant in labels(grid):
            for seed in grid.get("method_seeds", {}).get(m, grid["seeds"]):
                job = f"{sc['name']}__{m}__{variant}__s{seed}"
                path = os.path.join(out, "runs", job, "results.json")
                if not os.path.exists(path) or (only is not None and os.path.normpath(path) not in only):
                    missing.append(job)
                    continue
                with open(path) as fh:
                    r = json.load(fh)
                if "final_fit" not in r or "path" not in r["final_fit"]:
                    raise SystemExit(f"{path}: final_fit.path: missing (the run predates path evaluation)")
                runs[(sc["layout"], sc["name"], label, seed)] = r
    return runs, missing


def held(r):
    """Every view the run trained on: its initial views and the ones it chose."""
    return set(r.get("initial_views", [])) | set(r["selected_views"])


def longest_unheld_stretch(r):
    """The most consecutive views of the path, in the dataset's order, that the run held none
    of (the stretches before the first and after the last held view count; no wrapping)."""
    names = [v["name"] for v in r["final_fit"]["path"]]
    h = held(r)
    longest = run = 0
    for n in names:
        run = 0 if n in h else run + 1
        longest = max(longest, run)
    return longest


def path_psnr(r, exclude):
    vals = [v["psnr"] for v in r["final_fit"]["path"] if v["name"] not in exclude]
    return sum(vals) / len(vals)


def two_level_bootstrap(by_scene, rng):
    """by_scene: {scene: [values over seeds]}. (mean of scene means, low, high); low and high
    are nan for one scene with one seed."""
    scenes = sorted(by_scene)
    def stat(sample):
        return sum(sum(v) / len(v) for v in sample) / len(sample)
    point = stat([by_scene[s] for s in scenes])
    if len(scenes) < 2 and all(len(v) < 2 for v in by_scene.values()):
        return point, float("nan"), float("nan")
    draws = []
    for _ in range(DRAWS):
        sample = []
        for _ in scenes:
            vals = by_scene[scenes[rng.randrange(len(scenes))]]
            sample.append([vals[rng.randrange(len(vals))] for _ in vals])
        draws.append(stat(sample))
    draws.sort()
    return point, draws[int(0.025 * DRAWS)], draws[int(0.975 * DRAWS) - 1]


def paired_diffs(have, scenes, seeds, m, base):
    """m minus base per scene, over the trainer seeds both ran: ({scene: [along-path
    differences over the views neither held]}, {scene: [test-view PSNR differences]}, pairs)."""
    path_by, test_by, pairs = {}, {}, 0
    for s in scenes:
        for seed in seeds:
            a, b = have.get((s, m, seed)), have.get((s, base, seed))
            if a is None or b is None:
                continue
            both = held(a) | held(b)
            path_by.setdefault(s, []).append(path_psnr(a, both) - path_psnr(b, both))
            test_by.setdefault(s, []).append(a["final_fit"]["psnr"] - b["final_fit"]["psnr"])
            pairs += 1
    return path_by, test_by, pairs


def fmt(x, digits=3):
    return "n/a" if x != x else f"{x:.{digits}f}"


def path_by_name(r):
    return {v["name"]: v["psnr"] for v in r["final_fit"]["path"]}


def per_view_panel(scene, have, better, series_methods, seeds):
    """One scene's panel: for each method, view by view along the path, its final fit's PSNR
    minus the better baseline's, the mean over the trainer seeds where neither run held the
    view (a gap where every seed held it); dashed: the test views; under the axis the views
    each method held (opacity: share of seeds). None when the baseline has no run here."""
    base_runs = {seed: have[(scene, better, seed)] for seed in seeds if (scene, better, seed) in have}
    if not base_runs:
        return None
    order = [v["name"] for v in next(iter(base_runs.values()))["final_fit"]["path"]]
    index = {n: i for i, n in enumerate(order)}
    test = sorted({index[v["name"]] for r in base_runs.values() for v in r.get("views", []) if v["name"] in index})
    # The strips in the series' order, the baseline's last, so that each method's ticks take
    # its line's colour (svg_plot colours both by position).
    series, strips, legend = [], [], []
    for m in list(series_methods) + [better]:
        runs = {seed: have[(scene, m, seed)] for seed in seeds if (scene, m, seed) in have}
        if not runs:
            continue
        share = {}
        for r in runs.values():
            for n in held(r):
                if n in index:
                    share[index[n]] = share.get(index[n], 0.0) + 1.0 / len(runs)
        strips.append((m, share))
        if m == better:
            continue
        # Per paired seed, once: both runs' PSNR by view name and the views either held.
        paired = [(path_by_name(a), path_by_name(base_runs[seed]), held(a) | held(base_runs[seed]))
                  for seed, a in runs.items() if seed in base_runs]
        ys = []
        for n in order:
            d = [pa[n] - pb[n] for pa, pb, both in paired if n not in both]
            ys.append(sum(d) / len(d) if d else float("nan"))
        finite = [y for y in ys if y == y]
        series.append((m, ys))
        legend.append(f"{m} {sum(finite) / len(finite):+.2f}" if finite else m)
    if not series:
        return None
    return {"title": f"{scene}: final-fit PSNR minus {better}'s, view by view (mean over views: "
                     f"{', '.join(legend)} dB)",
            "xlabel": "view along the capture path; under the axis: the views each method held (opacity: share of "
                      "trainer seeds)",
            "ylabel": "difference (dB)", "n": len(order), "series": series, "marks": test, "strips": strips}


def tables(grid, out, only=None, figures=None, title="Verdict 3", command="python3 scripts/experiments/verdict3_tables.py"):
    """(markdown, csv) of the tables; `figures`, a dict, gets {capture type: SVG text} of the
    per-view figures."""
    runs, missing = load_runs(grid, out, only)
    judged = {}  # (capture, method): (pairs, scenes, diff, low, high)
    head = {}  # capture: (pairs, scenes, diff, low, high, scene means) of JUDGED[1] minus JUDGED[0]
    layouts = list(dict.fromkeys(sc["layout"] for sc in grid["scenes"]))
    methods = [label for label, _, _ in labels(grid)]
    method_of = {label: m for label, m, _ in labels(grid)}

    def seeds_of(label):
        return grid.get("method_seeds", {}).get(method_of.get(label, label), grid["seeds"])

    md, rows = [], []
    md.append(f"# {title}: selectors judged across scenes")
    md.append("")
    md.append(f"Generated by `{command}` from {out}/runs "
              f"({len(runs)} finished runs, {len(missing)} missing). Final fit of each method's own views; "
              "along the path = mean PSNR over every dataset view the run did not hold (paired: held by neither); "
              "intervals: two-level bootstrap (scenes, then trainer seeds within a scene), 95 %.")
    md.append("")
    for lay in layouts:
        scenes = [sc["name"] for sc in grid["scenes"] if sc["layout"] == lay]
        have = {(s, m, seed): r for (l, s, m, seed), r in runs.items() if l == lay}
        if not have:
            continue
        md.append(f"## {lay} ({len(scenes)} scene{'' if len(scenes) == 1 else 's'}: {', '.join(scenes)})")
        md.append("")
        md.append("| method | runs | along path, dB | test PSNR, dB | test SSIM | oracle's share | longest unheld stretch |")
        md.append("|---|---:|---:|---:|---:|---:|---:|")
        mean_path = {}
        for m in methods:
            rs = [r for (s, mm, seed), r in have.items() if mm == m]
            if not rs:
                continue
            mean_path[m] = sum(path_psnr(r, held(r)) for r in rs) / len(rs)
        for m in methods:
            rs = [r for (s, mm, seed), r in have.items() if mm == m]
            if not rs:
                continue
            test_psnr = sum(r["final_fit"]["psnr"] for r in rs) / len(rs)
            test_ssim = sum(r["final_fit"]["ssim"] for r in rs) / len(rs)
            share = float("nan")
            if "random" in mean_path and "oracle" in mean_path and mean_path["oracle"] != mean_path["random"]:
                share = (mean_path[m] - mean_path["random"]) / (mean_path["oracle"] - mean_path["random"])
            stretch = sum(longest_unheld_stretch(r) for r in rs) / len(rs)
            md.append(f"| {m} | {len(rs)} | {fmt(mean_path[m])} | {fmt(test_psnr)} | {fmt(test_ssim, 4)} | {fmt(share, 2)} | "
                      f"{stretch:.1f} |")
            rows.append({"table": "methods", "capture": lay, "method": m, "runs": len(rs), "path_psnr": mean_path[m],
                         "test_psnr": test_psnr, "test_ssim": test_ssim, "oracle_share": share,
                         "longest_unheld": stretch})
        md.append("")
        base = [b for b in BASELINES if b in mean_path]
        if not base:
            continue
        better = max(base, key=lambda b: mean_path[b])
        md.append(f"Against the better baseline, **{better}** (paired by scene and trainer seed, along the path over "
                  "views neither run held; the test views' PSNR beside it):")
        md.append("")
        md.append("| method | pairs | scenes | along path: diff | low | high | test PSNR: diff | low | high | verdict |")
        md.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|")
        by_scene = {}
        for m in methods:
            if m == better:
                continue
            path_by, test_by, pairs = paired_diffs(have, scenes, seeds_of(m), m, better)
            if not pairs:
                continue
            # One generator per table cell, seeded by its name: a cell's interval does not
            # move when another method's runs land.
            d, lo, hi = two_level_bootstrap(path_by, random.Random(f"{lay}/{m}/path"))
            td, tlo, thi = two_level_bootstrap(test_by, random.Random(f"{lay}/{m}/test"))
            if len(path_by) < 2:
                verdict = "one scene: no verdict across scenes"
            elif lo > 0:
                verdict = "above, clear of 0"
            elif hi < 0:
                verdict = "below, clear of 0"
            elif lo > -0.1:
                verdict = "level (low end above -0.1)"
            else:
                verdict = "not shown level"
            md.append(f"| {m} | {pairs} | {len(path_by)} | {fmt(d)} | {fmt(lo)} | {fmt(hi)} | {fmt(td)} | {fmt(tlo)} | "
                      f"{fmt(thi)} | {verdict} |")
            by_scene[m] = {sc: sum(v) / len(v) for sc, v in path_by.items()}
            if m in JUDGED:
                judged[(lay, m)] = (pairs, len(path_by), d, lo, hi)
            rows.append({"table": "vs_better", "capture": lay, "method": m, "baseline": better, "pairs": pairs,
                         "scenes": len(path_by), "path_diff": d, "path_low": lo, "path_high": hi, "test_diff": td,
                         "test_low": tlo, "test_high": thi, "verdict": verdict})
        md.append("")
        # Scene by scene: whether a capture type's difference is one scene's or every scene's.
        md.append(f"Scene by scene (along the path, minus {better}, the mean over trainer seeds; first row: "
                  f"{better}'s own along-path PSNR):")
        md.append("")
        md.append("| method | " + " | ".join(scenes) + " |")
        md.append("|---|" + "---:|" * len(scenes))
        own = []
        for sc in scenes:
            rs = [r for (s2, mm, seed), r in have.items() if s2 == sc and mm == better]
            own.append(fmt(sum(path_psnr(r, held(r)) for r in rs) / len(rs)) if rs else "n/a")
        md.append(f"| {better} (dB) | " + " | ".join(own) + " |")
        for m in methods:
            if m in by_scene:
                md.append(f"| {m} | " + " | ".join(f"{by_scene[m][sc]:+.3f}" if sc in by_scene[m] else "n/a"
                                                   for sc in scenes) + " |")
        md.append("")
        a_m, b_m = JUDGED
        h_by, _, h_pairs = paired_diffs(have, scenes, seeds_of(b_m), b_m, a_m)
        if h_pairs:
            head[lay] = ((h_pairs, len(h_by)) + two_level_bootstrap(h_by, random.Random(f"{lay}/{b_m}-{a_m}/path"))
                         + (", ".join(f"{sum(h_by[s]) / len(h_by[s]):+.2f}" for s in scenes if s in h_by),))
        if figures is not None:
            seeds = sorted({seed for (_, _, seed) in have})
            panels = [p for p in (per_view_panel(sc, have, better, [m for m in methods if m in JUDGED or
                                                                     method_of[m] == "oracle"], seeds)
                                  for sc in scenes) if p]
            if panels:
                figures[lay] = svgText(panels, f"{lay}: the final fit's PSNR at every view of the path, each "
                                               f"method minus {better} (scripts/experiments/verdict3_tables.py)")
    md += bar_section(judged, layouts)
    md += head_section(head, layouts)
    if missing:
        md.append(f"Jobs not finished ({len(missing)}): " + ", ".join(missing))
        md.append("")
    text = "\n".join(md)
    buf = io.StringIO()
    keys = sorted({k for r in rows for k in r})
    w = csv.DictWriter(buf, fieldnames=keys, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: (f"{v:.6f}" if isinstance(v, float) else v) for k, v in r.items()})
    return text, buf.getvalue()


def bar_section(judged, layouts):
    """The judged selectors against issue 49's bar, capture type by capture type (nothing
    when none of them has a pair: a grid of other methods)."""
    if not judged:
        return []
    md = ["## The default and the new selector against the bar", "",
          f"Along the path against the better of fisher and fvs: the bar is a low end above {BAR_LOW} dB on every "
          f"capture type and clear of zero (low end above 0) on at least {BAR_CLEAR}.", "",
          "| method | capture | pairs | scenes | diff | low | high | low above " + f"{BAR_LOW}" + " | clear of 0 |",
          "|---|---|---:|---:|---:|---:|---:|---|---|"]
    for m in JUDGED:
        caps = [lay for lay in layouts if (lay, m) in judged]
        for lay in caps:
            pairs, nsc, d, lo, hi = judged[(lay, m)]
            md.append(f"| {m} | {lay} | {pairs} | {nsc} | {fmt(d)} | {fmt(lo)} | {fmt(hi)} | "
                      f"{'yes' if lo > BAR_LOW else 'no'} | {'yes' if lo > 0 else 'no'} |")
    md.append("")
    for m in JUDGED:
        caps = [lay for lay in layouts if (lay, m) in judged]
        if not caps:
            continue
        low_fail = [lay for lay in caps if not judged[(lay, m)][3] > BAR_LOW]
        clear = [lay for lay in caps if judged[(lay, m)][3] > 0]
        absent = [lay for lay in layouts if lay not in caps]
        met = not low_fail and len(clear) >= BAR_CLEAR and not absent
        md.append(f"- **{m}**: low end above {BAR_LOW} on {len(caps) - len(low_fail)} of {len(caps)} capture types"
                  + (f" (not on {', '.join(low_fail)})" if low_fail else "")
                  + f"; clear of zero on {len(clear)}" + (f" ({', '.join(clear)})" if clear else "")
                  + (f"; no pairs yet on {', '.join(absent)}" if absent else "")
                  + f": the bar is {'met' if met else 'not met'} on this grid's {len(layouts)} capture types.")
    md.append("")
    return md


def head_section(head, layouts):
    """JUDGED[1] minus JUDGED[0], capture type by capture type (nothing without a pair)."""
    if not head:
        return []
    a_m, b_m = JUDGED
    md = [f"## {b_m} against {a_m}", "",
          f"Along the path, {b_m} minus {a_m}, paired by scene and trainer seed over the views neither held "
          "(scene by scene: each scene's mean over trainer seeds, the scenes in the order above):", "",
          "| capture | pairs | scenes | diff | low | high | scene by scene |", "|---|---:|---:|---:|---:|---:|---|"]
    for lay in layouts:
        if lay in head:
            pairs, nsc, d, lo, hi, per_scene = head[lay]
            md.append(f"| {lay} | {pairs} | {nsc} | {fmt(d)} | {fmt(lo)} | {fmt(hi)} | {per_scene} |")
    md.append("")
    return md


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--grid", default="results/grid_verdict3.json")
    ap.add_argument("--out", default="results/verdict3")
    ap.add_argument("--name", default="verdict3", help="the tables' file name under OUT/tables (.md, .csv)")
    ap.add_argument("--check", action="store_true", help="compare with the committed tables; write nothing")
    a = ap.parse_args()
    with open(a.grid) as fh:
        grid = json.load(fh)
    # --check judges the committed runs alone (a grid still running leaves others on disk);
    # writing uses every finished run, to be committed with the tables.
    only = tracked_files(a.out) if a.check else None
    figures = {}
    command = "python3 scripts/experiments/verdict3_tables.py"
    if (a.grid, a.out, a.name) != (ap.get_default("grid"), ap.get_default("out"), ap.get_default("name")):
        command += f" --grid {a.grid} --out {a.out} --name {a.name}"
    md, csv_text = tables(grid, a.out, only, figures, "Verdict 3" if a.name == "verdict3" else a.name, command)
    files = {os.path.join(a.out, "tables", a.name + ".md"): md + "\n", os.path.join(a.out, "tables", a.name + ".csv"): csv_text}
    for lay, svg in figures.items():
        files[os.path.join(a.out, "plots", f"{a.name}_per_view_{lay}.svg")] = svg
    if a.check:
        stale = []
        for path, text in files.items():
            try:
                with open(path) as fh:
                    if fh.read() != text:
                        stale.append(path)
            except FileNotFoundError:
                stale.append(path)
        if stale:
            print("stale (regenerate with python3 scripts/experiments/verdict3_tables.py): " + ", ".join(stale))
            return 1
        print(f"verdict3 tables match the runs ({md.count(chr(10)) + 1} lines)")
        return 0
    for path, text in files.items():
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path + ".tmp", "w") as fh:
            fh.write(text)
        os.replace(path + ".tmp", path)
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
