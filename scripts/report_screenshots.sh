#!/usr/bin/env bash
# Regenerates the report screenshots the README shows (docs/report_run.png,
# docs/report_views.png, docs/report_grid.png): the main job's run page (run
# scripts/main.sh first) and the committed small grid's page, drawn by headless Chromium
# through tests/browser/page_probe.mjs. Usage: bash scripts/report_screenshots.sh
set -euo pipefail
cd "$(dirname "$0")/.."
run=out/active_sa-resgs
[ -f "$run/results.json" ] || { echo "report_screenshots: $run/results.json missing: run bash scripts/main.sh first" >&2; exit 1; }
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
./build/apps/saresgs report "$run" --out "$tmp/run.html"
./build/apps/saresgs report results/small --out "$tmp/grid.html"
shot() {  # page, expression, png
  node --experimental-websocket tests/browser/page_probe.mjs --chromium "$(command -v chromium)" \
    --url "file://$1" --eval "$2" --width 1280 --height 960 --screenshot "$3" --out "$tmp/probe.json" 2>/dev/null
  echo "report_screenshots: wrote $3"
}
# the viewer from the first test camera, then the step slider moved to show why a view was chosen
shot "$tmp/run.html" "saresgsReport.ready.then(() => new Promise((r) => setTimeout(r, 1500)))" docs/report_run.png
shot "$tmp/run.html" "(document.getElementById('views').scrollIntoView(), new Promise((r) => setTimeout(r, 500)))" docs/report_views.png
shot "$tmp/grid.html" "new Promise((r) => setTimeout(r, 300))" docs/report_grid.png
