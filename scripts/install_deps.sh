#!/usr/bin/env bash
# Installs every Debian 12 package saresgs needs. Idempotent: installs only what is
# missing, runs as root or through sudo. With --tests also what only the tests need (the
# browser the report's tests drive). Usage: bash scripts/install_deps.sh [--tests]
set -euo pipefail

packages=(
  # toolchain
  g++ cmake ninja-build pkg-config
  # libraries (one note each in third_party_notes/); OpenVDB's find module needs boost-iostreams too
  libembree-dev libopenvdb-dev libboost-iostreams-dev libtbb-dev libeigen3-dev
  libopencv-dev libcgal-dev libgtest-dev libbenchmark-dev nlohmann-json3-dev libcli11-dev
  # plain PNGs' inflate (geometry/image/png_decode.cpp)
  libdeflate-dev
  # COLMAP: the tests convert our models with `colmap model_converter`; `--sfm colmap`
  colmap libsqlite3-dev
  # the Python module (python/): pybind11, Debian's Python headers, NumPy, and pytest for its tests
  pybind11-dev python3-dev python3-numpy python3-pytest
  # GNU parallel: shards of an ablation grid on one machine (results/README.md)
  parallel
  # the fuzz targets (fuzz/): clang 14 and its runtimes (libFuzzer, ASan, UBSan), which
  # clang only recommends (third_party_notes/libfuzzer.md)
  clang-14 libclang-rt-14-dev
  # CC0 meshes (/usr/share/doc/libcgal-dev/data.tar.gz) and photographs for textures
  libcgal-demo opencv-doc
)

if [ "${1:-}" = "--tests" ]; then
  # the HTML report's browser tests: headless Chromium with software WebGL, and a font
  packages+=(chromium fonts-liberation)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  # splat-transform from npm: the .ply tests read our files with it.
  exec bash "${here}/install_node_tools.sh"
fi

bash "${here}/apt_install.sh" "${missing[@]}"
bash "${here}/install_node_tools.sh"
