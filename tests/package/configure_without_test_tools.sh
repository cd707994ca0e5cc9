#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# scripts/setup.sh installs only what the programs need, then configures build/: on a fresh
# machine GoogleTest and Google Benchmark are not there yet. This configures the source tree as
# setup.sh does, with both hidden from CMake, and checks that configuring succeeds, says where the
# tests come from, and still generates the programs' target.
#   configure_without_test_tools.sh SOURCE_DIR WORK_DIR
set -euo pipefail
src="$1" work="$2"
rm -rf "$work"
mkdir -p "$work"
log="$work/configure.log"
if ! cmake -S "$src" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_DISABLE_FIND_PACKAGE_GTest=ON -DCMAKE_DISABLE_FIND_PACKAGE_benchmark=ON \
  -DUNDERFOOT_BUILD_GUI=OFF > "$log" 2>&1; then
  cat "$log"
  echo "FAIL: configuring without GoogleTest and Google Benchmark failed (as on a fresh machine" \
    "after scripts/setup.sh's packages)"
  exit 1
fi
grep -q "GoogleTest not found: the tests are not configured" "$log" || {
  cat "$log"
  echo "FAIL: the configure log does not say that the tests are left out, and why"
  exit 1
}
# The target list goes to a file first: `grep -q` stops reading at the first match, and under
# pipefail the writer's SIGPIPE would fail the pipeline.
ninja -C "$work/build" -t targets all > "$work/targets.txt"
grep -q "^underfoot_programs:" "$work/targets.txt" || {
  echo "FAIL: no underfoot_programs target without the test tools"
  exit 1
}
if grep -q "^test_" "$work/targets.txt"; then
  echo "FAIL: test targets were generated although GoogleTest was hidden"
  exit 1
fi
echo "ok: configured without the test tools; programs only ($(wc -l < "$log") lines of log)"
rm -rf "$work"
