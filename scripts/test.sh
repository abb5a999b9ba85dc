#!/usr/bin/env bash
# The test command: install what is missing, build, run every test through CTest (the C++
# suites and the Python module's pytest files), then the Slurm path end to end on a
# one-node cluster of this machine (scripts/test_slurm.sh, about 40 s with its install).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh --tests  # with the browser the report's tests drive
bash scripts/build.sh -DSARESGS_FUZZ=ON -DSARESGS_WERROR=ON  # everything (tests, Python module, fuzz targets), no warning
ctest --test-dir build --output-on-failure --parallel "$(nproc)" --timeout 900
bash scripts/test_slurm.sh
