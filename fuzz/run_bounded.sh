#!/usr/bin/env bash
# The bounded fuzz run of the test command (CTest label `fuzz`, cmake/fuzz.cmake):
#   run_bounded.sh FUZZ_BINARY SEED_DIR TESTS_DIR WORK_DIR RUNS
# 1. every seed (SEED_DIR) must be read without error (SARESGS_FUZZ_EXPECT_VALID=1);
# 2. every committed regression input of this target (TESTS_DIR/**/fuzz_regressions/
#    <target>/, the inputs the fuzzers once failed on) must run clean under the
#    sanitizers, accepted or refused with an InputError;
# 3. RUNS inputs mutated from both, fixed random seed, in a fresh copy of the corpus.
# A crash, sanitizer report, leak, timeout, foreign exception or refused seed fails the
# test; the input that did it is left in WORK_DIR/artifacts (docs/FUZZING.md).
set -euo pipefail
bin=$1 seeds=$2 tests=$3 work=$4 runs=$5
target=$(basename "$bin")
target=${target#fuzz_}
rm -rf "$work"
mkdir -p "$work/corpus" "$work/artifacts"
shopt -s nullglob
files=("$seeds"/*)
if [ ${#files[@]} -eq 0 ]; then
  echo "run_bounded: no seeds in $seeds" >&2
  exit 1
fi
SARESGS_FUZZ_EXPECT_VALID=1 "$bin" "${files[@]}"
cp "${files[@]}" "$work/corpus/"
regressions=()
while IFS= read -r -d '' d; do
  regressions+=("$d"/*)
done < <(find "$tests" -type d -path "*/fuzz_regressions/$target" -print0)
if [ ${#regressions[@]} -gt 0 ]; then
  "$bin" "${regressions[@]}"
  cp "${regressions[@]}" "$work/corpus/"
fi
# AddressSanitizer keeps freed memory in a 256 MB quarantine by default; with its size-class
# caches and libFuzzer's corpus bookkeeping that made a million-run fuzz of `manifest` peak
# at 1.4 GB, which looked like a leak. Replaying one input 3000 times plateaus (152, 155,
# 156 MB after 100, 1000, 3000 runs; fuzz/replay_growth.sh), so the loaders keep nothing per
# call; a 32 MB quarantine still catches use-after-free of recent frees and keeps RSS near
# what the code uses. A user's own ASAN_OPTIONS come first.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}quarantine_size_mb=32"
exec "$bin" -seed=1 -runs="$runs" -timeout=10 -rss_limit_mb=2048 -max_len=16384 \
  -artifact_prefix="$work/artifacts/" -print_final_stats=1 "$work/corpus"
