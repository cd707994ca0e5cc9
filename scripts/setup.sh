#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Underfoot setup on Debian 12: installs the packages the programs need, builds the programs
# (underfoot, underfoot-gui, their man pages) into build/, and fetches the small set of recorded
# footsteps the realism tools compare with. The tests are built by scripts/test.sh.
#   bash scripts/setup.sh                          # packages + programs + small recordings
#   UNDERFOOT_SKIP_APT=1 bash scripts/setup.sh     # without apt-get (packages already there)
#   UNDERFOOT_RECORDINGS_LARGE=1 bash scripts/setup.sh   # also the three large recording
#                                                  # packages (about 1.24 GB more)
#   UNDERFOOT_SKIP_RECORDINGS=1 bash scripts/setup.sh    # no recordings
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/packages.sh

underfoot_install_packages setup "${UNDERFOOT_BUILD_PACKAGES[@]}"

# shellcheck disable=SC2046 # the launcher flags are words
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" $(underfoot_cmake_launcher)
cmake --build build --parallel "$(nproc)" --target underfoot_programs
echo "setup: built into build/ (programs: build/app/cli/underfoot, build/app/gui/underfoot-gui;" \
  "the tests are built by bash scripts/test.sh)"

# Recorded footsteps (Debian game data, fetched with apt-get download) for `underfoot compare` /
# `underfoot fit` and tests/realism, which skip, saying so, the tests that need more.
if [ "${UNDERFOOT_SKIP_RECORDINGS:-0}" = "1" ]; then
  echo "setup: UNDERFOOT_SKIP_RECORDINGS=1, no recorded footsteps fetched"
elif [ -L build/recordings ]; then
  echo "setup: build/recordings links to $(readlink build/recordings): left as it is"
elif [ "${UNDERFOOT_RECORDINGS_LARGE:-0}" = "1" ]; then
  bash scripts/fetch-recordings.sh --large build/recordings ||
    echo "setup: warning: could not fetch the recorded footsteps; tests/realism will skip those tests"
elif [ -f build/recordings/manifest.csv ]; then
  echo "setup: recorded footsteps already in build/recordings (bash scripts/fetch-recordings.sh" \
    "fetches them again)"
else
  bash scripts/fetch-recordings.sh build/recordings ||
    echo "setup: warning: could not fetch the recorded footsteps; tests/realism will skip those tests"
fi
if [ "${UNDERFOOT_RECORDINGS_LARGE:-0}" != "1" ]; then
  echo "setup: the large recording packages (nexuiz-data, openclonk-data, redeclipse-data," \
    "about 1.24 GB) are left out; UNDERFOOT_RECORDINGS_LARGE=1 bash scripts/setup.sh (or" \
    "bash scripts/fetch-recordings.sh --large) adds them"
fi
