#!/usr/bin/env bash
# The main job: install what is missing, build, make the built-in scene (room360), then
# run one SA-ResGS active reconstruction on it with the quick preset and print the final
# table. Outputs: out/builtin (the scene) and out/active_sa-resgs (the run). The plain
# refit that a verdict uses to judge selection apart from training is left out
# (--no-plain-refit): it would double the final fit's time.
set -euo pipefail
cd "$(dirname "$0")/.."
scene=out/builtin
run=out/active_sa-resgs
bash scripts/install_deps.sh
bash scripts/build.sh --target saresgs  # the program alone: the tests and fuzzers are test.sh's
[ -f "$scene/manifest.json" ] || ./build/apps/saresgs scene --layout room360 --out "$scene"
./build/apps/saresgs info --dataset "$scene"
# A finished run is replaced; an interrupted one continues from its checkpoint.
if [ -f "$run/results.json" ]; then rm -rf "$run"; fi
resume=""
[ -f "$run/checkpoint.json" ] && resume="--resume"
./build/apps/saresgs active --dataset "$scene" --method sa-resgs --preset quick --seed 0 --no-plain-refit --out "$run" $resume
