#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Underfoot tests: installs the test tools (Debian packages and the browser test's npm driver),
# builds and runs the release build's suites (GCC), then the same suites built with
# AddressSanitizer + UndefinedBehaviorSanitizer (clang 14 when installed), then a short fuzz pass.
#   bash scripts/test.sh                  # everything but long soaks
#   bash scripts/test.sh -L engine        # extra ctest arguments (here: one part) apply to both runs
#   UNDERFOOT_SKIP_APT=1 bash scripts/test.sh        # without apt-get (packages already there)
#   UNDERFOOT_SKIP_SANITIZE=1 bash scripts/test.sh   # the release run only
#   UNDERFOOT_SKIP_FUZZ=1 bash scripts/test.sh       # without the fuzz pass
#   UNDERFOOT_FUZZ_SECONDS=60 bash scripts/test.sh   # a longer fuzz pass (default 5 s per target)
#   UNDERFOOT_SERIAL_BUILDS=1 bash scripts/test.sh   # no build beside a test run (see below)
#   UNDERFOOT_SANITIZE_COMPILER=gcc bash scripts/test.sh   # the sanitizer build with GCC
#   UNDERFOOT_PACKAGE_TEST=1 bash scripts/test.sh    # also the package test (label package: root,
#                                                    # debootstrap and Debian's archive; 2-10 min)
# The fuzz pass (a third, small build with clang: only the reader libraries and the libFuzzer
# targets of tests/fuzz) replays every regression input and the seed corpus, then fuzzes each
# target for UNDERFOOT_FUZZ_SECONDS; it runs when no extra ctest arguments are given. Long soaks
# and fuzz campaigns carry the ctest label `soak` (ctest --test-dir build-fuzz -L soak), the
# package test the label `package` (ctest --test-dir build -L package): neither runs by default.
# Every build uses -g1 (line tables), unity batches (UNDERFOOT_UNITY) and ccache when present.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/packages.sh
jobs="$(nproc)"
launcher="$(underfoot_cmake_launcher)"

underfoot_install_packages test "${UNDERFOOT_BUILD_PACKAGES[@]}" "${UNDERFOOT_TEST_PACKAGES[@]}"
# Node.js and npm drive the browser test (puppeteer-core). Many machines already carry a newer
# Node.js than Debian's (whose npm package would conflict with it): Debian's only when there is
# none.
if ! command -v npm > /dev/null; then
  underfoot_install_packages test nodejs npm
fi
# The browser test's driver (puppeteer-core, pinned by package-lock.json; Debian's chromium is
# used, no browser download).
if [ -f tests/web/browser/package-lock.json ] && command -v npm > /dev/null &&
  [ ! -L tests/web/browser/node_modules ]; then
  (cd tests/web/browser && PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-audit --no-fund --silent)
fi

run_sanitize=0 run_fuzz=0
[ "${UNDERFOOT_SKIP_SANITIZE:-0}" != "1" ] && run_sanitize=1
if [ "${UNDERFOOT_SKIP_FUZZ:-0}" != "1" ] && [ $# -eq 0 ]; then
  if command -v clang++-14 > /dev/null; then
    run_fuzz=1
  else
    echo "== fuzz pass skipped: clang++-14 is not installed (bash scripts/test.sh installs it)"
  fi
fi

# The test runs leave most of the two cores idle (JACK, sockets, a browser, timers: a release
# run used 503 s of CPU in 1363 s), so the next build runs beside each test run, at a lower
# priority (docs/decisions/setup-and-ci-time.md). UNDERFOOT_SERIAL_BUILDS=1 runs them one after
# the other instead.
overlap=1
[ "${UNDERFOOT_SERIAL_BUILDS:-0}" = "1" ] && overlap=0
bg_pid="" bg_log=""
start_build() { # dir [cmake --build args...]: in the background when overlapping, else now
  local dir="$1"
  shift
  if [ $overlap = 1 ]; then
    bg_log="$dir/background-build.log"
    echo "== building $dir beside the tests (log: $bg_log)"
    nice -n 10 cmake --build "$dir" --parallel "$jobs" "$@" > "$bg_log" 2>&1 &
    bg_pid=$!
  else
    cmake --build "$dir" --parallel "$jobs" "$@"
  fi
}
finish_build() { # waits for the background build; its log on failure
  [ -n "$bg_pid" ] || return 0
  local status=0
  wait "$bg_pid" || status=$?
  bg_pid=""
  if [ $status != 0 ]; then
    tail -60 "$bg_log"
    echo "== the background build failed (log: $bg_log)"
    exit $status
  fi
}
trap '[ -n "$bg_pid" ] && kill "$bg_pid" 2> /dev/null' EXIT

if [ ! -f build/CMakeCache.txt ]; then
  # shellcheck disable=SC2086
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" $launcher
else
  # setup.sh configured build/ before the test tools were installed: configure again, so that
  # GoogleTest and Google Benchmark are found and the tests are added.
  cmake -S . -B build > /dev/null
fi
cmake --build build --parallel "$jobs"

if [ $run_sanitize = 1 ]; then
  if [ ! -f build-asan/CMakeCache.txt ]; then
    # clang 14 when installed (the test list installs it): the same 693 tests passed with it,
    # and the build took 902 s of CPU against GCC 12's 1460 s, the tests 602 s against 751 s
    # (docs/decisions/setup-and-ci-time.md). UNDERFOOT_SANITIZE_COMPILER=gcc keeps GCC.
    compilers=""
    if [ "${UNDERFOOT_SANITIZE_COMPILER:-clang}" = "clang" ] && command -v clang++-14 > /dev/null; then
      compilers="-DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14"
    fi
    # shellcheck disable=SC2086
    cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" \
      -DUNDERFOOT_SANITIZE=ON -DUNDERFOOT_BUILD_BENCHMARKS=OFF -DUNDERFOOT_BUILD_GUI=OFF \
      $compilers $launcher
  fi
  start_build build-asan
fi
echo "== tests (release build)"
release_status=0
ctest --test-dir build --output-on-failure -j "$jobs" -LE "soak|package" "$@" || release_status=$?
if [ "${UNDERFOOT_PACKAGE_TEST:-0}" = "1" ]; then
  echo "== package test (the .deb files installed with apt-get in a clean Debian root)"
  ctest --test-dir build --output-on-failure -L package || release_status=1
fi
finish_build
[ $release_status = 0 ] || exit $release_status

if [ $run_fuzz = 1 ]; then
  if [ ! -f build-fuzz/CMakeCache.txt ]; then
    # shellcheck disable=SC2086
    cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" \
      -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 -DUNDERFOOT_FUZZ=ON \
      -DUNDERFOOT_BUILD_BENCHMARKS=OFF -DUNDERFOOT_BUILD_GUI=OFF $launcher
  fi
  cmake -S . -B build-fuzz -DUNDERFOOT_FUZZ_SECONDS="${UNDERFOOT_FUZZ_SECONDS:-5}" > /dev/null
fi
if [ $run_sanitize = 1 ]; then
  [ $run_fuzz = 1 ] && start_build build-fuzz --target underfoot_fuzz
  echo "== tests (address + undefined sanitizers)"
  asan_status=0
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs" -LE "soak|nosan" "$@" || asan_status=$?
  finish_build
  [ $asan_status = 0 ] || exit $asan_status
elif [ $run_fuzz = 1 ]; then
  cmake --build build-fuzz --parallel "$jobs" --target underfoot_fuzz
fi

if [ $run_fuzz = 1 ]; then
  echo "== fuzz pass (libFuzzer + address + undefined sanitizers, regression inputs + ${UNDERFOOT_FUZZ_SECONDS:-5} s per target)"
  ctest --test-dir build-fuzz --output-on-failure -j "$jobs" -L fuzz
fi
