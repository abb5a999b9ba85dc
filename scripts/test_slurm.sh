#!/usr/bin/env bash
# End-to-end test of the Slurm path (scripts/slurm_ablate.sh) against the GNU parallel path,
# on a one-node cluster on this machine (scripts/slurm_local.sh; needs root). It runs a tiny
# ablation grid (2 methods x 2 seeds on a 64x48 room360 scene, a few seconds per job) as a
# 2-task array job, resubmits it to check that finished jobs are skipped, merges it, runs
# the same grid as 2 shards under GNU parallel, merges that, and checks that both give the
# same tables and the same per-job results (wall-clock seconds aside: runs are
# deterministic for a seed and thread count). Prints PASS or FAIL and the duration; exits
# non-zero on any mismatch, failure or timeout. The daemons are stopped on exit.
#   bash scripts/test_slurm.sh [WORKDIR]      (default: a new folder under /tmp, kept)
# SLURM_TEST_TIMEOUT (seconds, default 600) bounds each array job and the GNU parallel run.
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$(pwd)"
bin=./build/apps/saresgs
[ -x "$bin" ] || { echo "test_slurm: $bin is missing: build first (scripts/build.sh)" >&2; exit 1; }
limit="${SLURM_TEST_TIMEOUT:-600}"
start_s=$SECONDS
work="${1:-$(mktemp -d /tmp/saresgs-slurm-test.XXXXXX)}"
mkdir -p "$work"
work="$(cd "$work" && pwd)"  # absolute: the array tasks run from the repository root
scene="$work/scene"
grid="$work/grid.json"
out_slurm="$work/out_slurm"
out_par="$work/out_parallel"
logs="$work/slurm_logs"
job_id=""

fail() {
  echo "test_slurm: FAIL: $* (work dir $work, $((SECONDS - start_s)) s)" >&2
  exit 1
}

# On any exit: cancel our array job if it is still queued or running, then stop the
# daemons, so that a failed or interrupted test leaves nothing behind but its work dir.
cleanup() {
  local rc=$?
  if [ -n "$job_id" ] && squeue -h -j "$job_id" 2>/dev/null | grep -q .; then
    echo "test_slurm: cancelling job $job_id" >&2
    scancel "$job_id" 2>/dev/null || true
    # Let slurmd finish the tasks' cleanup before the controller goes away.
    for ((i = 0; i < 30; i++)); do
      squeue -h -j "$job_id" 2>/dev/null | grep -q . || break
      sleep 1
    done
  fi
  bash "$repo/scripts/slurm_local.sh" stop || true
  exit "$rc"
}
trap cleanup EXIT

# Submits the grid as a 2-task array (one shard each, as docs/CLUSTER.md says) and waits
# for it, at most $limit seconds. The wait polls squeue every second rather than using
# `sbatch --wait`, whose poll interval doubles up to 32 s (half a minute lost per array
# here); once the job has left the queue, `scontrol show job` still knows (for MinJobAge,
# 300 s) each task's state and exit code. `nice -n 5 sbatch`: the tasks inherit its nice
# value (PropagatePrioProcess=1 in slurm_local.sh's slurm.conf).
run_array() {
  local tag="$1" shown=0 t0=$SECONDS states
  mkdir -p "$logs"
  job_id="$(nice -n 5 sbatch --parsable --array=0-1 -o "$logs/${tag}_%A_%a.out" \
    scripts/slurm_ablate.sh "$grid" "$out_slurm" | cut -d';' -f1)" || fail "sbatch failed"
  [ -n "$job_id" ] || fail "sbatch gave no job id"
  echo "test_slurm: submitted array job $job_id ($tag)"
  while squeue -h -j "$job_id" 2>/dev/null | grep -q .; do
    if [ "$shown" -eq 0 ] && [ $((SECONDS - t0)) -ge 3 ]; then
      squeue -j "$job_id" || true  # both tasks should be running at once, one core each
      shown=1
    fi
    [ $((SECONDS - t0)) -lt "$limit" ] || fail "array job $job_id ($tag) not done after $limit s"
    sleep 1
  done
  states="$(scontrol -o show job "$job_id" | grep -o 'JobState=[A-Z_]* .*ExitCode=[0-9:]*' |
    sed -E 's/JobState=([A-Z_]*) .*ExitCode=([0-9:]*)/\1 \2/' | sort | uniq -c | tr -s ' ' | paste -sd,)"
  echo "test_slurm: array job $job_id ($tag) done after $((SECONDS - t0)) s: tasks${states}"
  if [ "$states" != " 2 COMPLETED 0:0" ]; then
    tail -n 20 "$logs/${tag}_${job_id}"_*.out >&2 || true
    fail "array job $job_id ($tag): tasks${states:- unknown}, expected 2 COMPLETED 0:0"
  fi
}

# 1. The cluster, from whatever state it is in (slurm_local.sh is idempotent).
bash scripts/slurm_local.sh

# 2. A tiny built-in scene and a grid of 4 short jobs: random and fvs, seeds 0 and 1, one
# thread each, 6 views, 150 loop iterations and a 40-iteration final fit.
# A reused work dir keeps its scene but never its results: every run trains every job.
rm -rf "$out_slurm" "$out_par" "$logs"
if [ ! -f "$scene/manifest.json" ]; then
  nice -n 5 "$bin" scene --layout room360 --out "$scene" --width 64 --height 48 --views 40 \
    >"$work/scene.log" 2>&1 || { tail -n 20 "$work/scene.log" >&2; fail "making the scene failed"; }
fi
cat >"$grid" <<EOF
{
  "comment": "scripts/test_slurm.sh: a tiny grid, a few seconds per job",
  "preset": "quick",
  "threads": 1,
  "scenes": [{"name": "room360", "dataset": "$scene"}],
  "methods": ["random", "fvs"],
  "seeds": [0, 1],
  "variants": [{"name": "tiny",
                "args": ["--max-views", "6", "--interval", "10", "--min-iterations", "120",
                         "--final-iterations", "40"]}]
}
EOF
jobs="$("$bin" ablate --config "$grid" --out "$out_slurm" --list | grep -c '^\[')"
[ "$jobs" -eq 4 ] || fail "the grid expands to $jobs jobs, expected 4"

# 3. The Slurm path: the array, then the same array again, which must only skip.
t_slurm=$SECONDS
run_array first
for t in 0 1; do
  f="$(ls "$logs"/first_"${job_id}"_"$t".out)"
  grep -q "shard $t/2 done" "$f" || fail "task $t did not finish its shard ($f)"
done
t_slurm=$((SECONDS - t_slurm))
stamp_before="$(stat -c '%n %Y' "$out_slurm"/runs/*/results.json)"
run_array again
skipped="$(cat "$logs"/again_"${job_id}"_*.out | grep -c 'finished before, skipped' || true)"
[ "$skipped" -eq 4 ] || fail "the resubmitted array skipped $skipped of 4 finished jobs"
[ "$stamp_before" = "$(stat -c '%n %Y' "$out_slurm"/runs/*/results.json)" ] ||
  fail "the resubmitted array rewrote finished results"
echo "test_slurm: resubmission skipped all 4 finished jobs"
nice -n 5 "$bin" ablate merge --config "$grid" --out "$out_slurm"

# 4. The GNU parallel path on the same grid: two shards on this machine.
t_par=$SECONDS
# Their progress goes to a log (shown on failure), as the array tasks' goes to slurm_logs/.
if ! timeout "$limit" nice -n 5 parallel --will-cite -j 2 --line-buffer \
  "$bin" ablate --config "$grid" --out "$out_par" --shard {}/2 ::: 0 1 >"$work/parallel.log" 2>&1; then
  tail -n 20 "$work/parallel.log" >&2
  fail "the GNU parallel shards failed or took over $limit s"
fi
t_par=$((SECONDS - t_par))
nice -n 5 "$bin" ablate merge --config "$grid" --out "$out_par"

# 5. Same tables (tables/*.csv) and same results.json per job. Wall-clock seconds and
# resident memory differ from run to run: the `seconds` and `memory` objects of
# results.json are left out, and of time.csv
# (every column but method and runs is a time or a ratio of times) only those two columns
# are compared. Everything else must match exactly, floats included.
if ! python3 - "$out_slurm" "$out_par" <<'EOF'
import csv, glob, json, os, sys

a, b = sys.argv[1], sys.argv[2]
errors = []

def tables(root):
    return sorted(os.path.basename(p) for p in glob.glob(os.path.join(root, "tables", "*.csv")))

def read_csv(path, keep=None):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if keep is None or not rows:
        return rows
    idx = [i for i, h in enumerate(rows[0]) if h in keep]
    return [[r[i] if i < len(r) else "" for i in idx] for r in rows]

ta, tb = tables(a), tables(b)
if ta != tb:
    errors.append(f"tables differ: {ta} vs {tb}")
if not ta:
    errors.append("no tables/*.csv")
for name in sorted(set(ta) & set(tb)):
    keep = {"method", "runs"} if name == "time.csv" else None
    ra = read_csv(os.path.join(a, "tables", name), keep)
    rb = read_csv(os.path.join(b, "tables", name), keep)
    if ra != rb:
        diff = [(i, x, y) for i, (x, y) in enumerate(zip(ra, rb)) if x != y][:3]
        errors.append(f"tables/{name} differs (rows {len(ra)} vs {len(rb)}): {diff}")

def strip(o):
    if isinstance(o, dict):
        return {k: strip(v) for k, v in o.items() if k not in ("seconds", "memory")}
    if isinstance(o, list):
        return [strip(v) for v in o]
    return o

def first_diff(x, y, path="$"):
    if type(x) != type(y):
        return f"{path}: {x!r} vs {y!r}"
    if isinstance(x, dict):
        for k in sorted(set(x) | set(y)):
            if k not in x or k not in y:
                return f"{path}.{k}: only in one"
            d = first_diff(x[k], y[k], f"{path}.{k}")
            if d:
                return d
    elif isinstance(x, list):
        if len(x) != len(y):
            return f"{path}: length {len(x)} vs {len(y)}"
        for i, (u, v) in enumerate(zip(x, y)):
            d = first_diff(u, v, f"{path}[{i}]")
            if d:
                return d
    elif x != y:
        return f"{path}: {x!r} vs {y!r}"
    return None

ja = sorted(os.path.basename(os.path.dirname(p)) for p in glob.glob(os.path.join(a, "runs", "*", "results.json")))
jb = sorted(os.path.basename(os.path.dirname(p)) for p in glob.glob(os.path.join(b, "runs", "*", "results.json")))
if ja != jb or len(ja) != 4:
    errors.append(f"finished jobs differ: {ja} vs {jb}")
for job in sorted(set(ja) & set(jb)):
    ra = json.load(open(os.path.join(a, "runs", job, "results.json")))
    rb = json.load(open(os.path.join(b, "runs", job, "results.json")))
    d = first_diff(strip(ra), strip(rb))
    print(f"  {job}: views {ra['selected_view_indices']} PSNR {ra['psnr']:.4f} final fit {ra['final_fit']['psnr']:.4f}"
          f" | parallel: views {rb['selected_view_indices']} PSNR {rb['psnr']:.4f} final fit {rb['final_fit']['psnr']:.4f}"
          + ("" if d is None else "  DIFFERS"))
    if d:
        errors.append(f"runs/{job}/results.json differs at {d}")
print(f"  compared tables: {', '.join(ta)}; per-job results.json: {len(ja)} jobs")
for e in errors:
    print("  mismatch: " + e, file=sys.stderr)
sys.exit(1 if errors else 0)
EOF
then
  fail "Slurm and GNU parallel results differ"
fi
echo "test_slurm: PASS: Slurm array (${t_slurm} s) and GNU parallel (${t_par} s) give the same tables and runs;" \
  "$((SECONDS - start_s)) s end to end (work dir $work)"
