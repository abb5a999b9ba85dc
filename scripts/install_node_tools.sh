#!/usr/bin/env bash
# Installs the Node.js tools into <repo>/build/node_tools:
#  - @playcanvas/splat-transform (reads and converts 3DGS .ply files): the tests read our
#    models with it;
#  - the HTML report's viewer (report/package.json: three.js and Spark, pinned by version
#    in report/package-lock.json) bundled by esbuild with report/web/viewer.js into one
#    script, report/viewer.js, which `saresgs report` inlines into every page.
# Idempotent: installs nodejs/npm from Debian only when missing, each npm package only when
# it is missing, and rebundles only when a source is newer than the bundle. Runs as root
# or through sudo. Usage: bash scripts/install_node_tools.sh
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
prefix="${repo}/build/node_tools"
tool="${prefix}/node_modules/.bin/splat-transform"

if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  bash "${repo}/scripts/apt_install.sh" nodejs npm
fi

if [ -x "${tool}" ]; then
  echo "install_node_tools: splat-transform present at ${tool}"
else
  mkdir -p "${prefix}"
  echo "install_node_tools: installing @playcanvas/splat-transform@3 into ${prefix}"
  npm install --no-audit --no-fund --prefix "${prefix}" @playcanvas/splat-transform@3
  [ -x "${tool}" ] || { echo "install_node_tools: ${tool} missing after npm install" >&2; exit 1; }
  echo "install_node_tools: installed $("${tool}" --version 2>&1 | head -n 1)"
fi

# The report's viewer: `npm ci` installs exactly the locked versions.
report="${prefix}/report"
bundle="${report}/viewer.js"
mkdir -p "${report}"
if ! cmp -s "${repo}/report/package-lock.json" "${report}/package-lock.json" || [ ! -d "${report}/node_modules" ]; then
  cp "${repo}/report/package.json" "${repo}/report/package-lock.json" "${report}/"
  echo "install_node_tools: installing the report's packages (report/package-lock.json) into ${report}"
  (cd "${report}" && npm ci --no-audit --no-fund)
  rm -f "${bundle}"
fi
if [ ! -s "${bundle}" ] || [ "${repo}/report/web/viewer.js" -nt "${bundle}" ]; then
  # One IIFE script (no modules, no network at view time); the WebAssembly Spark sorts with
  # is already inlined in its package. No source map: its comment would name a file the
  # page cannot reach.
  NODE_PATH="${report}/node_modules" "${report}/node_modules/.bin/esbuild" "${repo}/report/web/viewer.js" \
    --bundle --format=iife --minify --legal-comments=none --log-level=warning --outfile="${bundle}.tmp"
  grep -v '^//# sourceMappingURL=' "${bundle}.tmp" > "${bundle}.tmp2" || true
  rm -f "${bundle}.tmp"
  [ -s "${bundle}.tmp2" ] || { echo "install_node_tools: esbuild wrote nothing for ${bundle}" >&2; exit 1; }
  mv "${bundle}.tmp2" "${bundle}"
  echo "install_node_tools: bundled the report viewer into ${bundle} ($(wc -c < "${bundle}") bytes)"
else
  echo "install_node_tools: report viewer present at ${bundle}"
fi
