#!/usr/bin/env bash
# The main job: install what is missing, build, then make the built-in scene and
# print its summary. Output goes to out/builtin (override with the first argument).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/builtin}
bash scripts/install_deps.sh
bash scripts/build.sh
./build/apps/saresgs scene --layout room360 --out "$out"
./build/apps/saresgs info --dataset "$out"
