#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# `cmake --install` into a folder, then move that folder: the programs must find their data in
# <bin>/../share/underfoot (base/DataDir.h), not in the source tree, and their man pages must be
# there. Runs them from an unrelated folder with every data override unset.
#   install_tree.sh <build dir> <work dir>
set -euo pipefail
build="$(readlink -f "$1")"
work="$2"
rm -rf "$work" && mkdir -p "$work"
work="$(readlink -f "$work")"
unset UNDERFOOT_DATA_DIR UNDERFOOT_SURFACES_DIR UNDERFOOT_IR_DIR UNDERFOOT_GRF_BANK_DIR \
    UNDERFOOT_WADING_DIR UNDERFOOT_SOUNDSCAPES_DIR UNDERFOOT_PROTOCOLS_DIR UNDERFOOT_GUI_DATA_DIR

cmake --install "$build" --prefix "$work/first" > "$work/install.log"
mv "$work/first" "$work/moved" # relocatable: nothing may point at the first prefix
prefix="$work/moved"
uf="$prefix/bin/underfoot"
share="$prefix/share/underfoot"
mkdir -p "$work/run" && cd "$work/run"

fail() { echo "FAIL: $*"; exit 1; }
for d in surfaces ir grf wading soundscapes protocols protocols/data protocols/simulation; do
    [ -d "$share/$d" ] || fail "share/underfoot/$d was not installed"
done
[ -f "$prefix/share/man/man1/underfoot.1" ] || fail "no man page underfoot.1"
[ -f "$prefix/share/man/man1/underfoot-render.1" ] || fail "no man page underfoot-render.1"

"$uf" --version | grep -Eq '^underfoot [0-9]+\.[0-9]+\.[0-9]+ \(commit [0-9a-f]{12}(-dirty)?|unknown\)' ||
    fail "underfoot --version: $("$uf" --version)"
n_presets=$(ls "$share"/surfaces/*.toml | wc -l)
n_listed=$("$uf" surfaces | grep -c '^[a-z_]* ' || true)
[ "$n_listed" = "$n_presets" ] || fail "underfoot surfaces lists $n_listed surfaces, $n_presets installed"

"$uf" render --all -o out --seconds 2 -q
n_out=$(ls out/*.wav | wc -l)
[ "$n_out" = "$n_presets" ] || fail "render --all wrote $n_out files for $n_presets surfaces"

"$uf" protocol check "$share/protocols/tvcg2011_exp2.toml" > check.txt
"$uf" soundscape list | grep -q forest || fail "soundscape list does not name forest"
"$uf" wade --depth deep --seconds 2 -o wade.wav > /dev/null
"$uf" protocol power "$share/protocols/tvcg2011_exp2.toml" --participants 10 --simulations 20 \
    --no-mixed > power.txt 2> power.err || fail "protocol power could not read the shipped matrices"
# The presets are read from the installed folder, not the source tree: a copy of wood added
# there is listed (its id is inside the file, so wood shows twice).
cp "$share/surfaces/wood.toml" "$share/surfaces/zz_installed_copy.toml"
[ "$("$uf" surfaces | grep -c '^wood ')" = 2 ] || fail "underfoot surfaces does not read $share/surfaces"
rm "$share/surfaces/zz_installed_copy.toml"

gui="$prefix/bin/underfoot-gui"
if [ -x "$gui" ]; then
    [ -f "$prefix/share/applications/underfoot-gui.desktop" ] || fail "no desktop entry"
    [ -f "$prefix/share/icons/hicolor/scalable/apps/underfoot.svg" ] || fail "no icon"
    env -u DISPLAY -u WAYLAND_DISPLAY -u QT_QPA_PLATFORM XDG_RUNTIME_DIR="$work" "$gui" --help |
        grep -q -- --study ||
        fail "underfoot-gui --help without a display"
    # Its own HOME: the console reopens the last study named in ~/.config, not the demo.
    HOME="$work" XDG_CONFIG_HOME="$work/config" QT_QPA_PLATFORM=offscreen XDG_RUNTIME_DIR="$work" \
        "$gui" --data-dir "$work/gui" \
        --screenshot "$work/shots" > gui.log 2>&1 || fail "underfoot-gui --screenshot: $(tail -5 gui.log)"
    [ -f "$work/gui/demo_study.db" ] || fail "the console made no demo study from share/underfoot/gui"
fi
echo "ok: installed tree in $prefix ran with its own data ($n_presets surfaces)"
