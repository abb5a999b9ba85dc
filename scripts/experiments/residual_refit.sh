#!/usr/bin/env bash
# Refit the views of finished active runs with the paper's residual supervision (train --residual).
# `saresgs train --residual` on exactly a run's views (initial, then selected) with its final fit's options
# (the quick preset's iterations, the run's Gaussian cap, SH degree 0, the run's seed, one
# thread), the fit `saresgs active` would have made had the method trained residually (the
# test Cli.FinalFitEqualsTrainOnTheChosenViews holds the two equal). It asks what a
# plain-training selector's views are worth with the paper's training, so that a selection
# and a training can be paired apart from each other.
#
#   BIN=path/to/saresgs bash scripts/experiments/residual_refit.sh OUTDIR results/verdict2/runs/JOB ...
#
# Writes OUTDIR/JOB/refit.json (train's results.json, with "source_run" and "source_final_fit_psnr"
# added) through a temporary name; a JOB that has one is skipped, so it can be stopped and
# started again. BIN: the binary that ran the runs (default ./build/apps/saresgs); the runs'
# own plain final fit must reproduce with it (checked: a plain refit of the first run is
# made too and compared to the last digit, as scripts/experiments/refit_final_fit.sh does).
set -uo pipefail
cd "$(dirname "$0")/../.."
bin=${BIN:-./build/apps/saresgs}
outdir=${1:?usage: residual_refit.sh OUTDIR RUN...}
shift
[ -x "$bin" ] || { echo "residual_refit: no binary $bin" >&2; exit 2; }
mkdir -p "$outdir"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
status=0
checked=0
for run in "$@"; do
  run=${run%/}
  job=$(basename "$run")
  [ -f "$outdir/$job/refit.json" ] && { echo "skip $job: done"; continue; }
  [ -f "$run/results.json" ] || { echo "skip $job: no results.json"; continue; }
  read -r ds views seed psnr residual iters preset cap < <(/usr/bin/python3 scripts/experiments/run_fit_options.py "$run/results.json") || { echo "FAIL $job: results.json has no final fit"; status=1; continue; }
  [ "$residual" = False ] || { echo "skip $job: its final fit already trains residually"; continue; }
  [ "$preset" = quick ] || { echo "skip $job: preset $preset (only the quick preset's final fit)"; continue; }
  train=("$bin" train --dataset "$ds" --views "$views" --iterations "$iters" --max-gaussians "$cap" --sh-degree 0
         --seed "$seed" --threads 1)
  if [ $checked = 0 ]; then
    "${train[@]}" --out "$tmp/plain" > "$tmp/plain.log" 2>&1 || { echo "FAIL $job: plain refit failed"; tail -3 "$tmp/plain.log"; exit 1; }
    got=$(/usr/bin/python3 -c "import json, sys; print(repr(json.load(open(sys.argv[1]))['psnr']))" "$tmp/plain/results.json")
    [ "$got" = "$psnr" ] || { echo "residual_refit: $bin does not reproduce $job's final fit ($got against $psnr)" >&2; exit 1; }
    echo "check $job: the plain refit reproduces the run's final fit ($psnr)"
    checked=1
  fi
  out=$tmp/$job
  if ! "${train[@]}" --residual --out "$out" > "$tmp/$job.log" 2>&1; then
    echo "FAIL $job: saresgs train --residual failed:"; tail -3 "$tmp/$job.log"; status=1; continue
  fi
  mkdir -p "$outdir/$job"
  # Written through a temporary name; prints the refit's PSNR for the log line.
  got=$(/usr/bin/python3 - "$out/results.json" "$outdir/$job/refit.json" "$run" "$psnr" <<'EOF'
import json, os, sys
src, dst, run, psnr = sys.argv[1:]
r = json.load(open(src))
r["source_run"] = run
r["source_final_fit_psnr"] = float(psnr)
with open(dst + ".tmp", "w") as fh:
    json.dump(r, fh, indent=1)
os.replace(dst + ".tmp", dst)
print(round(r["psnr"], 3))
EOF
) || { status=1; continue; }
  echo "ok $job: residual $got, plain $psnr"
  rm -rf "$out"
done
exit $status
