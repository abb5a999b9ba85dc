#!/usr/bin/env bash
# A long fuzz run of one target (docs/FUZZING.md), after `bash scripts/build.sh -DSARESGS_FUZZ=ON`:
#   bash fuzz/run_long.sh TARGET [RUNS] [WORK_DIR]
# RUNS inputs (default 1000000) mutated from the seeds (fuzz/corpus/TARGET) and the
# committed regression inputs (tests/**/fuzz_regressions/TARGET), with the limits of the
# test command's bounded run (fuzz/run_bounded.sh). The corpus grows in WORK_DIR/corpus
# (default build/fuzz/long/TARGET) and is reused by the next run; a failing input is
# written to WORK_DIR/artifacts and the run stops non-zero. The last lines are
# libFuzzer's figures: executions, executions per second, coverage, peak memory.
set -euo pipefail
cd "$(dirname "$0")/.."
target=$1 runs=${2:-1000000} work=${3:-build/fuzz/long/$1}
bin=build/fuzz/fuzz_$target
[ -x "$bin" ] || { echo "run_long: $bin is missing; build first (bash scripts/build.sh -DSARESGS_FUZZ=ON)" >&2; exit 2; }
mkdir -p "$work/corpus" "$work/artifacts"
extra=()
while IFS= read -r -d '' d; do extra+=("$d"); done \
  < <(find tests -type d -path "*/fuzz_regressions/$target" -print0)
# AddressSanitizer keeps freed memory in a 256 MB quarantine by default; with its size-class
# caches and libFuzzer's corpus bookkeeping that made a million-run fuzz of `manifest` peak
# at 1.4 GB, which looked like a leak. Replaying one input 3000 times plateaus (152, 155,
# 156 MB after 100, 1000, 3000 runs; fuzz/replay_growth.sh), so the loaders keep nothing per
# call; a 32 MB quarantine still catches use-after-free of recent frees and keeps RSS near
# what the code uses. A user's own ASAN_OPTIONS come first.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}quarantine_size_mb=32"
exec "$bin" -seed=1 -runs="$runs" -timeout=10 -rss_limit_mb=2048 -max_len=16384 \
  -artifact_prefix="$work/artifacts/" -print_final_stats=1 \
  "$work/corpus" "fuzz/corpus/$target" "${extra[@]}"
