#!/usr/bin/env bash
# Installs the named Debian packages, as root or through sudo (shared by the install
# scripts). Usage: bash scripts/apt_install.sh PACKAGE...
set -euo pipefail
[ $# -gt 0 ] || exit 0
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "apt_install: need root or sudo to install: $*" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
echo "apt_install: installing $*"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "$@"
