#!/usr/bin/env bash
# The C++ test suite under ThreadSanitizer, in its own build folder (build-tsan/,
# RelWithDebInfo), against a ThreadSanitizer build of oneTBB made from Debian's own source
# package of the libtbb we link (apt-get source onetbb, Debian's patches applied).
#
# Why TBB is rebuilt: Debian's libtbb.so is not instrumented, so ThreadSanitizer cannot see
# the happens-before edges of TBB's task queues and reports every hand-over between a
# parallel_for's tasks as a race, in TBB's headers and in our loop bodies alike (a
# 13-line parallel_for gave 66-68 such reports per run against Debian's libtbb and none
# against the instrumented one). Suppressing those would hide real races in our code too,
# so the suppressions file (scripts/tsan.supp) holds only reviewed findings about
# libraries we cannot rebuild (Embree, OpenCV, GDAL) and TBB's bookkeeping after them, each
# with its reason.
#
# Which tests: every C++ test (the TBB-parallel ones among them: rasterizer, Fisher,
# SSIM, Adam, triangulation, candidate sets, the synthetic renderer and the CLI's runs);
# the Python module and the fuzz targets are left out as in
# scripts/test_sanitizers.sh. Any report fails the test that made it (halt_on_error).
# Usage: bash scripts/test_tsan.sh [extra ctest arguments, e.g. -R Rasterizer]
# On two cores beside two single-thread ablation jobs oneTBB builds in about 17 s, the
# project in about 15 minutes and the suite in about 32 minutes (the slowest test, a whole
# training through the CLI, about 19). Not run by CI, whose budget it would exceed; run it
# before resolving a change to threading.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$(pwd)"
bash scripts/install_deps.sh
tsan="${root}/build-tsan"
tbb_prefix="${tsan}/tbb"
mkdir -p "${tsan}"

# 1. oneTBB with -fsanitize=thread, from the source package of the installed libtbb-dev.
if [ ! -f "${tbb_prefix}/lib/libtbb.so.12" ]; then
  version="$(dpkg-query -W -f='${Version}' libtbb-dev)"
  src="${tsan}/tbb-src"
  rm -rf "${src}" && mkdir -p "${src}"
  list=/etc/apt/sources.list.d/saresgs-deb-src.sources
  if ! apt-get source --print-uris "onetbb=${version}" >/dev/null 2>&1; then
    # The machine lists no source archive: add Debian's (the list stays, named saresgs-).
    sudo_=""; [ "$(id -u)" -eq 0 ] || sudo_="sudo"
    printf 'Types: deb-src\nURIs: http://deb.debian.org/debian\nSuites: bookworm bookworm-updates\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' |
      ${sudo_} tee "${list}" >/dev/null
    ${sudo_} apt-get update >/dev/null
  fi
  (cd "${src}" && apt-get source --download-only "onetbb=${version}" >/dev/null 2>&1 &&
    dpkg-source -x onetbb_*.dsc tbb >/dev/null)
  # -Wno-tsan: GCC warns that ThreadSanitizer does not model atomic_thread_fence (TBB
  # uses a few); TBB_STRICT=OFF keeps that warning from being an error.
  cmake -S "${src}/tbb" -B "${src}/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DTBB_SANITIZE=thread -DTBB_STRICT=OFF -DCMAKE_CXX_FLAGS=-Wno-tsan -DTBB_TEST=OFF \
    -DTBB_EXAMPLES=OFF -DTBBMALLOC_BUILD=OFF -DCMAKE_INSTALL_PREFIX="${tbb_prefix}" >/dev/null
  cmake --build "${src}/build" --parallel "$(nproc)" >/dev/null
  cmake --install "${src}/build" >/dev/null
fi

# 2. saresgs with -fsanitize=thread, linked (rpath) against that TBB. OpenVDB and Embree
# load libtbb.so.12 by soname, so they get the instrumented one too.
flags="-fsanitize=thread -fno-omit-frame-pointer"
cmake -S . -B "${tsan}/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_PREFIX_PATH="${tbb_prefix}" -DTBB_DIR="${tbb_prefix}/lib/cmake/TBB" \
  -DCMAKE_CXX_FLAGS="${flags}" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread -Wl,-rpath,${tbb_prefix}/lib" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=thread -Wl,-rpath,${tbb_prefix}/lib" \
  -DSARESGS_PYTHON=OFF -DSARESGS_FUZZ=OFF >/dev/null
cmake --build "${tsan}/build" --parallel "$(nproc)"
for exe in "${tsan}"/build/tests/test_* "${tsan}/build/apps/saresgs"; do
  [ -f "${exe}" ] && [ -x "${exe}" ] || continue
  # (ldd's output is read whole first: grep -q closing the pipe early would fail the
  # pipeline under pipefail.)
  libs="$(ldd "${exe}")"
  if [[ "${libs}" != *"${tbb_prefix}/lib/libtbb.so.12"* ]]; then
    echo "test_tsan: ${exe} does not load the instrumented libtbb (ldd: $(grep tbb <<<"${libs}"))" >&2
    exit 1
  fi
done

# 3. The harness can fail: a parallel_for whose body adds to one shared counter without a
# lock must be reported with these suppressions in force (and a correct one must not),
# or a clean suite below would prove nothing.
export TSAN_OPTIONS="halt_on_error=1:suppressions=${root}/scripts/tsan.supp"
canary="${tsan}/canary"
mkdir -p "${canary}"
cat > "${canary}/canary.cpp" <<'CPP'
#include <tbb/parallel_for.h>
#include <atomic>
#include <cstdio>
#include <cstring>
int main(int argc, char** argv) {
  const bool racy = argc > 1 && std::strcmp(argv[1], "racy") == 0;
  long plain = 0;
  std::atomic<long> safe{0};
  tbb::parallel_for(0, 100000, [&](int i) {
    if (racy) plain += i; else safe += i;
  });
  std::printf("%ld\n", racy ? plain : safe.load());
}
CPP
g++ -std=c++20 -O1 -g -fsanitize=thread -I"${tbb_prefix}/include" "${canary}/canary.cpp" -L"${tbb_prefix}/lib" -ltbb \
  -Wl,-rpath,"${tbb_prefix}/lib" -o "${canary}/canary"
if "${canary}/canary" racy >"${canary}/racy.log" 2>&1 || ! grep -q "data race" "${canary}/racy.log"; then
  echo "test_tsan: the deliberately racy canary was not reported; ThreadSanitizer would miss races" >&2
  exit 1
fi
if ! "${canary}/canary" >"${canary}/safe.log" 2>&1; then
  echo "test_tsan: the race-free canary was reported (false positives in TBB itself):" >&2
  cat "${canary}/safe.log" >&2
  exit 1
fi
echo "test_tsan: canary ok (a racy parallel_for reported, a race-free one clean)"

# 4. The suite. halt_on_error: the first report fails its test with both stacks;
# second_deadlock_stack: lock-order reports name both acquisitions.
# history_size=7: the most memory for old accesses, so both stacks of a report are kept.
export TSAN_OPTIONS="${TSAN_OPTIONS}:second_deadlock_stack=1:history_size=7"
export LD_LIBRARY_PATH="${tbb_prefix}/lib${LD_LIBRARY_PATH:+:${LD_LIBRARY_PATH}}"
ctest --test-dir "${tsan}/build" --output-on-failure --parallel "$(nproc)" --timeout 3600 "$@"
