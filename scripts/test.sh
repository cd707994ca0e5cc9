#!/usr/bin/env bash
# Underfoot tests: the release build's suites, then the same suites built with
# AddressSanitizer + UndefinedBehaviorSanitizer.
#   bash scripts/test.sh                  # everything but long soaks
#   bash scripts/test.sh -L engine        # extra ctest arguments (here: one part) apply to both runs
#   UNDERFOOT_SKIP_SANITIZE=1 bash scripts/test.sh   # the release run only
#   UNDERFOOT_SKIP_FUZZ=1 bash scripts/test.sh       # without the short fuzz pass
# The fuzz pass (a third, small build with clang: only the reader libraries and the libFuzzer
# targets of tests/fuzz) replays every regression input and fuzzes each target for
# UNDERFOOT_FUZZ_SECONDS (20 s); it runs when no extra ctest arguments are given.
# Long soaks carry the ctest label `soak` and run with: ctest --test-dir build -L soak
# Every build uses -g1 (line tables: file:line in sanitizer reports) and unity batches
# (UNDERFOOT_UNITY), which keep the three builds within CI's time.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc)"

if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG"
fi
cmake --build build --parallel "$jobs"
echo "== tests (release build)"
ctest --test-dir build --output-on-failure -j "$jobs" -LE soak "$@"

if [ "${UNDERFOOT_SKIP_SANITIZE:-0}" != "1" ]; then
  if [ ! -f build-asan/CMakeCache.txt ]; then
    cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" \
      -DUNDERFOOT_SANITIZE=ON -DUNDERFOOT_BUILD_BENCHMARKS=OFF -DUNDERFOOT_BUILD_GUI=OFF
  fi
  cmake --build build-asan --parallel "$jobs"
  echo "== tests (address + undefined sanitizers)"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs" -LE "soak|nosan" "$@"
fi

if [ "${UNDERFOOT_SKIP_FUZZ:-0}" != "1" ] && [ $# -eq 0 ]; then
  if ! command -v clang++-14 > /dev/null; then
    echo "== fuzz pass skipped: clang++-14 is not installed (bash scripts/setup.sh installs it)"
  else
    if [ ! -f build-fuzz/CMakeCache.txt ]; then
      cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" \
        -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 -DUNDERFOOT_FUZZ=ON \
        -DUNDERFOOT_BUILD_BENCHMARKS=OFF -DUNDERFOOT_BUILD_GUI=OFF
    fi
    cmake -S . -B build-fuzz -DUNDERFOOT_FUZZ_SECONDS="${UNDERFOOT_FUZZ_SECONDS:-20}" > /dev/null
    cmake --build build-fuzz --parallel "$jobs" --target underfoot_fuzz
    echo "== fuzz pass (libFuzzer + address + undefined sanitizers, regression inputs + ${UNDERFOOT_FUZZ_SECONDS:-20} s per target)"
    ctest --test-dir build-fuzz --output-on-failure -j "$jobs" -L fuzz
  fi
fi
