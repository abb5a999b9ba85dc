#!/usr/bin/env bash
# Installs the Node.js tools the tests run against our outputs: @playcanvas/splat-transform
# (reads and converts 3DGS .ply files) into <repo>/build/node_tools. Idempotent: installs
# nodejs/npm from Debian only when missing, and the npm package only when its binary is
# missing. Runs as root or through sudo. Usage: bash scripts/install_node_tools.sh
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
prefix="${repo}/build/node_tools"
tool="${prefix}/node_modules/.bin/splat-transform"

if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  bash "${repo}/scripts/apt_install.sh" nodejs npm
fi

if [ -x "${tool}" ]; then
  echo "install_node_tools: splat-transform present at ${tool}"
  exit 0
fi
mkdir -p "${prefix}"
echo "install_node_tools: installing @playcanvas/splat-transform@3 into ${prefix}"
npm install --no-audit --no-fund --prefix "${prefix}" @playcanvas/splat-transform@3
[ -x "${tool}" ] || { echo "install_node_tools: ${tool} missing after npm install" >&2; exit 1; }
echo "install_node_tools: installed $("${tool}" --version 2>&1 | head -n 1)"
