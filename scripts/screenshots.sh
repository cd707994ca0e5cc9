#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# One PNG per main view of underfoot-gui at 1280x800, rendered under Xvfb, for reviewing the look.
#
#   scripts/screenshots.sh [OUTPUT_DIR] [PATH/TO/underfoot-gui]
#
# Builds nothing: uses build/app/gui/underfoot-gui unless a path is given (or $UNDERFOOT_GUI).
# Runs with a scratch data folder (a fresh demo study), so the user's studies are not touched;
# the Run view's trial page is shot on a scratch copy of that study.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$here/build/screenshots}"
gui="${2:-${UNDERFOOT_GUI:-$here/build/app/gui/underfoot-gui}}"

if [[ ! -x "$gui" ]]; then
    echo "screenshots.sh: $gui is not an executable; build underfoot-gui first" \
         "(cmake --build build --target underfoot-gui) or pass its path as the second argument" >&2
    exit 2
fi
if ! command -v xvfb-run >/dev/null; then
    echo "screenshots.sh: xvfb-run not found; install the xvfb package (scripts/setup.sh)" >&2
    exit 2
fi

scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$out"
# A private settings folder too, so no "last study" of the user is opened.
XDG_CONFIG_HOME="$scratch/config" XDG_RUNTIME_DIR="$scratch" QT_QPA_PLATFORM=xcb \
    xvfb-run --auto-servernum --server-args="-screen 0 1280x800x24" \
    "$gui" --data-dir "$scratch/data" --screenshot "$out"
ls -1 "$out"/*.png
