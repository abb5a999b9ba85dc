#!/usr/bin/env bash
# Faults, with nothing lost (issue 25): a full disk under training, an active run and an
# ablation merge, and an ablation runner killed at random moments. Each trial checks that
# the failure is a clear error naming the file, that the last good files are intact, and
# that resuming after the fault gives exactly what a run without it gives.
#
#   bash scripts/fault_trials.sh [TRIALS]      (default 20 kill trials)
#
# Needs root (it mounts small tmpfs file systems to fill) and a built tree (scripts/build.sh).
# Not part of scripts/test.sh: CI's container may not mount. Prints the counts: trials,
# files compared, bytes lost (must be 0). Exits non-zero on any failed check.
set -euo pipefail
cd "$(dirname "$0")/.."
trials=${1:-20}
cli=$PWD/build/apps/saresgs
[ -x "$cli" ] || { echo "fault_trials: $cli missing: run bash scripts/build.sh" >&2; exit 2; }
[ "$(id -u)" = 0 ] || { echo "fault_trials: needs root to mount the small tmpfs file systems it fills" >&2; exit 2; }
work=$(mktemp -d /tmp/saresgs-faults.XXXXXX)
mnt=$work/disk
mkdir -p "$mnt"
cleanup() { umount "$mnt" 2>/dev/null || true; rm -rf "$work"; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
compared=0 lost=0
# Same content, timing and machine-state fields aside (JSON files: seconds, threads used,
# resident memory (peak and per phase) and the memory budget, which without --memory-budget is the memory free at the
# start), or same bytes.
same() {
  compared=$((compared + 1))
  /usr/bin/python3 - "$1" "$2" <<'EOF' || { lost=$((lost + $(stat -c %s "$1"))); return 1; }
import json, sys
a, b = sys.argv[1:3]
if not a.endswith(".json"):
    sys.exit(0 if open(a, "rb").read() == open(b, "rb").read() else 1)
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items()
                if "second" not in k and "rss" not in k and k not in ("threads_used", "budget_bytes")}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
sys.exit(0 if strip(json.load(open(a))) == strip(json.load(open(b))) else 1)
EOF
}
disk() {  # disk SIZE: a fresh tmpfs of SIZE at $mnt
  umount "$mnt" 2>/dev/null || true
  mount -t tmpfs -o size="$1" tmpfs "$mnt"
}

echo "fault_trials: tiny scene into $work" >&2
"$cli" scene --layout object --views 12 --width 64 --height 48 --out "$work/tiny" >/dev/null 2>&1

# 1. Training on a disk that fills between two checkpoints: the second checkpoint fails
#    with the file named, the first stays loadable, and --resume on a bigger disk ends
#    on the model of an uninterrupted run, bit for bit.
train=(train --dataset "$work/tiny" --iterations 60 --checkpoint-every 20 --seed 3)
"$cli" "${train[@]}" --out "$work/train_ref" >/dev/null 2>&1
ck=$(stat -c %s "$work/train_ref/checkpoint.bin")
disk $((ck * 3 / 2))   # room for one checkpoint, not for its replacement beside it
if "$cli" "${train[@]}" --out "$mnt/run" > "$work/train_full.log" 2>&1; then fail "training on a full disk exited 0"; fi
grep -q "$mnt/run/checkpoint.bin.*disk full" "$work/train_full.log" || fail "no clear error naming the checkpoint: $(tail -1 "$work/train_full.log")"
[ -s "$mnt/run/checkpoint.bin" ] || fail "the first checkpoint was lost"
ls "$mnt/run" | grep -qv -E '^(checkpoint\.bin|checkpoint\.json)$' && fail "files left beside the checkpoint: $(ls "$mnt/run")"
mount -o remount,size=64m "$mnt"
"$cli" "${train[@]}" --out "$mnt/run" --resume >/dev/null 2>&1 || fail "resume after freeing space failed"
same "$mnt/run/point_cloud.ply" "$work/train_ref/point_cloud.ply" || fail "resumed model differs from the uninterrupted one"
same "$mnt/run/results.json" "$work/train_ref/results.json" || fail "resumed results differ"
echo "  full disk under training: clear error, checkpoint kept, resumed model identical" >&2

# 2. An active run on disks too small for it, grown step by step: each attempt fails
#    naming a file, and the run that finally completes equals a run without faults.
active=(active --dataset "$work/tiny" --method fisher --max-views 5 --interval 3 --min-iterations 30 --final-iterations 20 --seed 1)
"$cli" "${active[@]}" --out "$work/active_ref" >/dev/null 2>&1
disk 64k
attempts=0
for size in 64k 256k 1m 4m 16m 64m; do
  mount -o remount,size=$size "$mnt"
  resume=""
  [ -f "$mnt/active/checkpoint.json" ] && resume=--resume
  attempts=$((attempts + 1))
  if "$cli" "${active[@]}" --out "$mnt/active" $resume > "$work/active.log" 2>&1; then break; fi
  grep -qE "$mnt/active/[^ ]*: .*(disk full|No space)" "$work/active.log" ||
    fail "active run on a full disk ($size): no clear error naming the file: $(tail -1 "$work/active.log")"
done
[ -f "$mnt/active/results.json" ] || fail "the active run never completed"
for f in results.json point_cloud.ply final_fit.ply; do
  same "$mnt/active/$f" "$work/active_ref/$f" || fail "active run after $attempts disk-full attempts: $f differs"
done
echo "  full disk under an active run: $attempts attempts, completed run identical" >&2

# 3. An ablation merge into a full disk: the error names the file and the earlier tables
#    are intact; a merge with space rewrites them equal.
grid=$work/grid.json
cat > "$grid" <<EOF
{"scenes": [{"name": "tiny", "dataset": "$work/tiny", "layout": "object"}],
 "methods": ["random", "fvs"], "seeds": [0, 1], "threads": 1,
 "variants": [{"name": "default", "args": ["--max-views", "5", "--interval", "3", "--min-iterations", "30", "--final-iterations", "20"]}]}
EOF
"$cli" ablate --config "$grid" --out "$work/grid_ref" >/dev/null 2>&1 || fail "clean grid run failed"
disk 64m
cp -r "$work/grid_ref" "$mnt/grid"
cp "$mnt/grid/tables/results.csv" "$work/results_before.csv"
used=$(du -sk "$mnt" | cut -f1)
mount -o remount,size=$((used + 8))k "$mnt"
if "$cli" ablate merge --config "$grid" --out "$mnt/grid" > "$work/merge.log" 2>&1; then
  echo "  (the merge fitted in 8 kB of free space; filling the rest)" >&2
fi
dd if=/dev/zero of="$mnt/fill" bs=1k count=100000 2>/dev/null || true
if "$cli" ablate merge --config "$grid" --out "$mnt/grid" > "$work/merge.log" 2>&1; then fail "a merge on a full disk exited 0"; fi
grep -qE "$mnt/grid/[^ ]*: .*(disk full|No space)" "$work/merge.log" || fail "merge on a full disk: no clear error naming the file: $(tail -1 "$work/merge.log")"
same "$mnt/grid/tables/results.csv" "$work/results_before.csv" || fail "a failed merge damaged results.csv"
rm -f "$mnt/fill"
mount -o remount,size=64m "$mnt"
"$cli" ablate merge --config "$grid" --out "$mnt/grid" >/dev/null 2>&1 || fail "merge after freeing space failed"
for t in results.csv paired.csv; do same "$mnt/grid/tables/$t" "$work/grid_ref/tables/$t" || fail "merged $t differs"; done
echo "  full disk under a merge: clear error, tables intact, merged again equal" >&2
umount "$mnt"

# 4. The ablation runner killed (SIGKILL, no clean-up) at random moments, restarted each
#    time; when it completes, every job's files equal a clean run's.
# Sixteen jobs (eight seeds), so that the trials' runners find work left to be killed in.
kgrid=$work/kill_grid.json
sed 's/"seeds": \[0, 1\]/"seeds": [0, 1, 2, 3, 4, 5, 6, 7]/' "$grid" > "$kgrid"
"$cli" ablate --config "$kgrid" --out "$work/kill_ref" >/dev/null 2>&1 || fail "clean run of the kill grid failed"
RANDOM=12345
out=$work/killed
kills=0
for t in $(seq 1 "$trials"); do
  "$cli" ablate --config "$kgrid" --out "$out" >> "$work/kill.log" 2>&1 &
  pid=$!
  sleep "$((RANDOM % 2)).$(printf '%03d' $((RANDOM % 1000)))"
  if kill -9 "$pid" 2>/dev/null; then kills=$((kills + 1)); fi
  wait "$pid" 2>/dev/null || true
done
"$cli" ablate --config "$kgrid" --out "$out" >> "$work/kill.log" 2>&1 || fail "the runner did not complete after the kills"
for d in "$work"/kill_ref/runs/*/; do
  job=$(basename "$d")
  for f in results.json point_cloud.ply final_fit.ply; do
    [ -f "$d/$f" ] || continue
    same "$out/runs/$job/$f" "$d/$f" || fail "after $kills kills: $job/$f differs from the clean run's"
  done
done
for t in results.csv paired.csv; do same "$out/tables/$t" "$work/kill_ref/tables/$t" || fail "after the kills: $t differs"; done
resumed=$(grep -c "^resuming from " "$work/kill.log" || true)
echo "  runner killed $kills times in $trials trials at random moments ($resumed resumed from a checkpoint): every job's files equal a clean run's" >&2
echo "fault_trials: PASS; kill trials $trials ($kills killed mid-run), files compared $compared, bytes lost $lost"
