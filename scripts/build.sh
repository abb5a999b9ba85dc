#!/usr/bin/env bash
# Configures and builds saresgs (Release) into build/. `--target NAME` (repeatable) builds
# only those targets and what they link (scripts/main.sh builds the `saresgs` program alone:
# no tests, fuzzers or Python module); every other argument goes to CMake's configure step.
set -euo pipefail
cd "$(dirname "$0")/.."
configure=()
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --target) targets+=(--target "$2"); shift 2 ;;
    *) configure+=("$1"); shift ;;
  esac
done
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "${configure[@]}" >/dev/null
cmake --build build --parallel "$(nproc)" "${targets[@]}"
