#!/usr/bin/env bash
# Underfoot setup: installs every Debian 12 package the project uses, then configures and builds.
#   bash scripts/setup.sh            # packages + release build in build/
#   UNDERFOOT_SKIP_APT=1 bash scripts/setup.sh   # build only (packages already there)
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake ninja-build pkg-config git clang-format
  # engine / io
  libsndfile1-dev libsamplerate0-dev libfftw3-dev libzita-convolver-dev
  librtaudio-dev libserialport-dev liblo-dev jackd2 libjack-jackd2-dev socat
  # files, CLI, formatting
  libtomlplusplus-dev libcli11-dev libfmt-dev nlohmann-json3-dev
  # statistics, real-time containers, and the HTTP server of `underfoot serve` (Beast, Asio)
  libboost-dev
  # mixed-effects models (analysis/stats/MixedModels): linear algebra and optimisation
  libeigen3-dev libnlopt-cxx-dev
  # modal estimate of recorded strikes (realism/Modal.cpp): LAPACK's drivers
  liblapacke-dev
  # storage
  libsqlite3-dev libsqlitecpp-dev sqlite3
  # SHA-256 of protocol texts (experiment/)
  libssl-dev
  # GUI
  qt6-base-dev qt6-charts-dev libqt6opengl6-dev libqt6sql6-sqlite libgl-dev xvfb xauth
  qt6-svg-dev  # console figures exported as SVG (QSvgGenerator)
  # tests and benchmarks
  googletest libgtest-dev libgmock-dev libbenchmark-dev valgrind
  # online listening tests: the browser test drives Debian's Chromium with puppeteer-core from
  # npm (tests/web/browser)
  chromium
  # fuzzing (libFuzzer: tests/fuzz, scripts/test.sh's fuzz build)
  clang-14 libclang-rt-14-dev
)

if [ "${UNDERFOOT_SKIP_APT:-0}" != "1" ]; then
  SUDO=""
  if [ "$(id -u)" != "0" ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  # Node.js and npm drive the browser test (puppeteer-core). Many machines already carry a
  # newer Node.js than Debian's (whose npm package would conflict with it): install Debian's
  # only when there is none.
  if ! command -v npm > /dev/null; then
    for p in nodejs npm; do
      dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
  fi
  if [ ${#missing[@]} -gt 0 ]; then
    echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
    $SUDO apt-get update -qq
    $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
  else
    echo "setup: all ${#PACKAGES[@]} Debian packages already installed"
  fi
fi

# The browser test's driver (puppeteer-core, pinned by package-lock.json; Debian's chromium is
# used, no browser download).
if [ -f tests/web/browser/package-lock.json ] && command -v npm > /dev/null; then
  (cd tests/web/browser && PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-audit --no-fund --silent)
fi

# -g1: line tables only (file:line in backtraces, profiles and sanitizer reports), for a faster
# build than full debug information; configure your own build with -g to step through locals.
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG"
cmake --build build --parallel "$(nproc)"
echo "setup: built into build/ (program: build/app/cli/underfoot)"
# Recorded footsteps (Debian game data packages, fetched with apt-get download) for
# `underfoot compare` / `underfoot fit` and tests/realism, which skip them when they are absent.
bash scripts/fetch-recordings.sh build/recordings ||
  echo "setup: warning: could not fetch the recorded footsteps; tests/realism will skip those tests"
