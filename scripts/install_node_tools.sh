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
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "install_node_tools: need root or sudo to install nodejs npm" >&2; exit 1; }
    sudo_cmd=(sudo)
  fi
  echo "install_node_tools: installing nodejs npm"
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends nodejs npm
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
