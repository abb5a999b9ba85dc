#!/usr/bin/env bash
# The whole C++ test suite under AddressSanitizer + UndefinedBehaviorSanitizer, in its own
# build folder (build-asan/, RelWithDebInfo). Any memory error, leak or undefined
# behaviour fails the run: UBSan is made fatal (-fno-sanitize-recover) and ASan reports
# leaks at exit. Usage: bash scripts/test_sanitizers.sh [extra ctest arguments]
#
# Left out, and why: the Python module (its tests would need the interpreter started with
# libasan preloaded; the module is a thin layer over the same libraries, whose tests run
# here) and the libFuzzer targets (they are built with clang and ASan already, and run in
# the main suite). The splat-transform tests use the tool scripts/install_node_tools.sh
# installed under build/, so run scripts/test.sh (or install_node_tools.sh) once first.
# On two cores the build takes about 25 minutes and the suite about 10.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS="${flags}" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DSARESGS_PYTHON=OFF -DSARESGS_FUZZ=OFF >/dev/null
cmake --build build-asan --parallel "$(nproc)"
# detect_leaks: a leak fails the test that leaks; halt_on_error and print_stacktrace: the
# first UB stops the test with where it happened.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:check_initialization_order=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
ctest --test-dir build-asan --output-on-failure --parallel "$(nproc)" --timeout 3600 "$@"
