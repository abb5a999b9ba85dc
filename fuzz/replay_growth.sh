#!/usr/bin/env bash
# Does one fuzz target keep memory per call? Runs each of the first seeds of the target
# (fuzz/corpus/TARGET) FEW and then MANY times in replay mode (no mutation, no corpus
# growth) with a 1 MB sanitizer quarantine and compares the peak RSS: a loader that keeps
# something per call (a growing cache, a referenced leak that LeakSanitizer cannot see)
# grows with the count; one that does not plateaus. Exits 1 when the growth exceeds
# LIMIT_KB per extra call (default 2 KB).
#   bash fuzz/replay_growth.sh TARGET [FEW=100] [MANY=2000] [SEEDS=5]
set -euo pipefail
cd "$(dirname "$0")/.."
target=$1 few=${2:-100} many=${3:-2000} seeds=${4:-5} limit_kb=${LIMIT_KB:-2}
bin=build/fuzz/fuzz_$target
[ -x "$bin" ] || { echo "replay_growth: $bin is missing; build first (bash scripts/build.sh -DSARESGS_FUZZ=ON)" >&2; exit 2; }
peak() {  # peak RSS in KB of N replays of file F
  local n=$1 f=$2 list=()
  for _ in $(seq "$n"); do list+=("$f"); done
  ASAN_OPTIONS=quarantine_size_mb=1:detect_leaks=0 /usr/bin/time -f "%M" "$bin" "${list[@]}" 2>&1 >/dev/null | tail -1
}
status=0
for f in $(ls -d "fuzz/corpus/$target"/* | head -"$seeds"); do
  a=$(peak "$few" "$f") b=$(peak "$many" "$f")
  per=$(( (b - a) * 1000 / (many - few) ))
  echo "$(basename "$f"): $a KB after $few calls, $b KB after $many: $((per / 1000)).$(printf '%03d' $((per % 1000))) KB per call"
  [ $(( (b - a) )) -le $(( limit_kb * (many - few) )) ] || status=1
done
[ $status = 0 ] && echo "replay_growth $target: no growth per call" || echo "replay_growth $target: GROWS per call" >&2
exit $status
