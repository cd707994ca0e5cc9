# SPDX-License-Identifier: GPL-3.0-or-later
# The Debian 12 packages Underfoot needs, in two lists, and the function that installs the
# missing ones. Sourced by scripts/setup.sh (the build list) and scripts/test.sh (the test list).
# Measured in a fresh debootstrap --variant=minbase root (docs/decisions/setup-and-ci-time.md):
# the build list is 229 MB in 312 packages, the test list adds 235 MB in 477 packages.

# To build and run the programs (setup.sh).
UNDERFOOT_BUILD_PACKAGES=(
  build-essential cmake ninja-build pkg-config git python3 ccache
  # engine / io
  libsndfile1-dev libsamplerate0-dev libfftw3-dev libzita-convolver-dev
  librtaudio-dev libserialport-dev liblo-dev libjack-jackd2-dev
  jackd2 # the usual audio server of the live path
  # files, CLI, formatting
  libtomlplusplus-dev libcli11-dev libfmt-dev nlohmann-json3-dev
  # statistics and real-time containers
  libboost-dev
  # mixed-effects models (analysis/stats/MixedModels): linear algebra and optimisation
  libeigen3-dev libnlopt-cxx-dev
  # modal estimate of recorded strikes (realism/Modal.cpp): LAPACK's drivers
  liblapacke-dev
  # storage; SHA-256 of protocol texts (experiment/)
  libsqlite3-dev libsqlitecpp-dev libssl-dev
  # online listening tests (`underfoot serve`, app/web): HTTP server
  libcpp-httplib-dev
  # the console
  qt6-base-dev qt6-charts-dev libqt6opengl6-dev libqt6sql6-sqlite libgl-dev
  qt6-svg-dev # console figures exported as SVG (QSvgGenerator)
)

# To build and run the tests, the fuzz pass, the package test and the tools (test.sh).
UNDERFOOT_TEST_PACKAGES=(
  googletest libgtest-dev libgmock-dev libbenchmark-dev valgrind
  # live tests: emulated shoes on pseudo-terminals (JACK's dummy driver comes with jackd2)
  socat
  # tests/app (a damaged study), the console's screenshots (scripts/screenshots.sh), style
  sqlite3 xvfb xauth clang-format
  # the browser test drives Debian's Chromium with puppeteer-core from npm (tests/web/browser)
  chromium
  # fuzzing (libFuzzer: tests/fuzz, scripts/test.sh's fuzz build)
  clang-14 libclang-rt-14-dev
  # the package test: a clean Debian root (tests/package/deb_install.sh)
  debootstrap
)

# underfoot_install_packages NAME PACKAGE...: installs the missing ones with apt-get (root or
# sudo), unless UNDERFOOT_SKIP_APT=1.
underfoot_install_packages() {
  local what="$1"
  shift
  if [ "${UNDERFOOT_SKIP_APT:-0}" = "1" ]; then
    echo "$what: UNDERFOOT_SKIP_APT=1, no Debian packages installed"
    return 0
  fi
  local sudo="" missing=() p
  if [ "$(id -u)" != "0" ]; then sudo="sudo"; fi
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2> /dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "$what: installing ${#missing[@]} Debian packages: ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    $sudo apt-get update -qq
    $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
  else
    echo "$what: all $# Debian packages already installed"
  fi
}

# ccache when it is there; its base directory is the checkout, so that two checkouts (or a
# moved one) share their objects: no object but base/DataDir.cpp's holds an absolute path of the
# checkout (base/CMakeLists.txt).
if command -v ccache > /dev/null; then
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}"
fi
underfoot_cmake_launcher() {
  if command -v ccache > /dev/null; then
    echo "-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache"
  fi
}
