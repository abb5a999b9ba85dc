#!/usr/bin/env bash
# The main job's run over several seeds with two binaries, paired by seed (final-fit PSNR).
# Does a change cost quality, or is one seed's final-fit PSNR the luck of its selection?
#
#   bash scripts/experiments/main_job_seeds.sh NEW_BIN BASE_BIN [SEEDS] [OUT]
#
# Runs `active --dataset out/builtin --method sa-resgs --preset quick --seed S` (with
# --no-plain-refit where the binary has it, as scripts/main.sh does) for every seed in
# SEEDS (default "0 1 2 3 4 5 6 7") and both binaries, two jobs at a time on one thread
# each (every stage gives the same bits for any thread count, so a seed's run is the one
# main.sh would make). Writes OUT/seeds.jsonl (default results/perf/main_job_seeds) and
# prints the paired table with a Student-t 95 % interval. Not a test: about 25 minutes on
# two cores for eight seeds. out/builtin must exist (bash scripts/main.sh makes it).
set -euo pipefail
new=$(realpath "$1"); base=$(realpath "$2"); seeds=${3:-"0 1 2 3 4 5 6 7"}
out=${4:-results/perf/main_job_seeds}
cd "$(dirname "$0")/../.."
[ -d out/builtin ] || { echo "main_job_seeds.sh: out/builtin is missing; run bash scripts/main.sh first" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
one() {  # who bin seed
  local who=$1 bin=$2 s=$3 extra="" help
  help=$("$bin" active --help)
  if grep -q -- --no-plain-refit <<< "$help"; then extra=--no-plain-refit; fi
  local t0=$(date +%s%N)
  "$bin" active --dataset out/builtin --method sa-resgs --preset quick --seed "$s" --threads 1 $extra \
    --out "$work/${who}_$s" > "$work/${who}_$s.log" 2>&1
  local t1=$(date +%s%N)
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(json.dumps({'who': sys.argv[2], 'seed': int(sys.argv[3]), 'final_fit_psnr': d['final_fit']['psnr'], 'loop_psnr': d['psnr'], 'views': d['selected_view_indices'], 'seconds_one_thread': float(sys.argv[4]), 'args': sys.argv[5]}))" \
    "$work/${who}_$s/results.json" "$who" "$s" "$(( (t1 - t0) / 1000000 ))e-3" "$extra" > "$work/${who}_$s.json"
}
export -f one; export work
for s in $seeds; do echo "new $new $s"; echo "base $base $s"; done | xargs -P 2 -L 1 bash -c 'one "$@"' _
mkdir -p "$out"
cat "$work"/*.json > "$out/seeds.jsonl.tmp" && mv "$out/seeds.jsonl.tmp" "$out/seeds.jsonl"
python3 - "$out/seeds.jsonl" <<'PY'
import json, sys
sys.path.insert(0, "scripts/experiments")
from table_io import interval95
rows = [json.loads(l) for l in open(sys.argv[1])]
by = {(r["who"], r["seed"]): r for r in rows}
seeds = sorted({r["seed"] for r in rows})
print("| seed | this tree, final fit dB | base, final fit dB | difference | views part at |")
print("|---:|---:|---:|---:|---:|")
diffs = []
for s in seeds:
    n, b = by[("new", s)], by[("base", s)]
    part = next((k + 1 for k, (x, y) in enumerate(zip(n["views"], b["views"])) if x != y), None)
    diffs.append(n["final_fit_psnr"] - b["final_fit_psnr"])
    print(f"| {s} | {n['final_fit_psnr']:.2f} | {b['final_fit_psnr']:.2f} | {diffs[-1]:+.2f} | {part or '-'} |")
m, lo, hi = interval95(diffs)
print(f"mean difference {m:+.2f} dB, 95 % interval [{lo:+.2f}, {hi:+.2f}] over {len(diffs)} seeds")
PY
