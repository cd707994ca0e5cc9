#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Makes the Debian packages a lab installs without building: underfoot_<version>-1_amd64.deb (the
# command line, its data, man pages) and underfoot-gui_<version>-1_amd64.deb (the console).
#   bash scripts/package.sh            # packages + programs in build-package/, the .deb files in
#                                      # build-package/packages/
# Then, on any Debian 12 machine:  sudo apt-get install ./underfoot_*.deb ./underfoot-gui_*.deb
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/packages.sh
underfoot_install_packages package "${UNDERFOOT_BUILD_PACKAGES[@]}"
# shellcheck disable=SC2046
cmake -S . -B build-package -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DCMAKE_INSTALL_PREFIX=/usr \
  -DUNDERFOOT_BUILD_TESTS=OFF -DUNDERFOOT_BUILD_BENCHMARKS=OFF $(underfoot_cmake_launcher)
cmake --build build-package --parallel "$(nproc)" --target underfoot_programs
(cd build-package && cpack -G DEB)
ls -l build-package/packages/*.deb
