#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The Debian packages, as a lab installs them: cpack makes underfoot_*.deb (and
# underfoot-gui_*.deb when the console is built); a clean Debian 12 root (debootstrap
# --variant=minbase, nothing of this machine in it) installs them with `apt-get install
# ./underfoot_*.deb`, which fetches their Depends from Debian's archive, and runs
# `underfoot render --all -o /tmp/x` (and the console's --help and screenshots) there.
#   deb_install.sh <build dir> <work dir>
# Needs root (chroot, mount), debootstrap and Debian's archive; skips (exit 77) saying which is
# missing. The minbase root is made once and kept as a tarball (UNDERFOOT_PACKAGE_ROOT, default
# <build dir>/package-root/bookworm-minbase.tar); UNDERFOOT_DEBIAN_MIRROR picks the archive.
set -euo pipefail
build="$(readlink -f "$1")"
work="$2"
mirror="${UNDERFOOT_DEBIAN_MIRROR:-http://deb.debian.org/debian}"
cache="${UNDERFOOT_PACKAGE_ROOT:-$build/package-root/bookworm-minbase.tar}"

skip() { echo "SKIP: $*"; exit 77; }
[ "$(id -u)" = 0 ] || skip "needs root (chroot and mount of /proc in the clean root)"
command -v debootstrap > /dev/null || skip "needs debootstrap (apt-get install debootstrap)"
command -v dpkg-deb > /dev/null || skip "needs dpkg-deb"

rm -rf "$work" && mkdir -p "$work"
work="$(readlink -f "$work")"
root="$work/root"
cleanup() {
    mountpoint -q "$root/proc" 2> /dev/null && umount "$root/proc"
    # never into a /proc that is still mounted
    mountpoint -q "$root/proc" 2> /dev/null || rm -rf --one-file-system "$root"
}
trap cleanup EXIT
t0=$SECONDS
step() { echo "== $* ($((SECONDS - t0)) s)"; }

step "packages (cpack)"
rm -rf "$build/packages"
(cd "$build" && cpack -G DEB > "$work/cpack.log" 2>&1) || {
    tail -20 "$work/cpack.log"
    echo "FAIL: cpack"
    exit 1
}
debs=("$build"/packages/underfoot_*.deb)
[ -f "${debs[0]}" ] || { echo "FAIL: cpack made no underfoot_*.deb"; exit 1; }
ls -l "$build"/packages/*.deb

if [ ! -f "$cache" ]; then
    step "clean Debian 12 root (debootstrap --variant=minbase bookworm $mirror)"
    mkdir -p "$(dirname "$cache")"
    rm -rf "$work/bootstrap"
    debootstrap --variant=minbase bookworm "$work/bootstrap" "$mirror" > "$work/debootstrap.log" 2>&1 || {
        tail -5 "$work/debootstrap.log"
        skip "debootstrap could not fetch Debian 12 from $mirror (no network?)"
    }
    tar -C "$work/bootstrap" -cf "$cache.partial" . && mv "$cache.partial" "$cache"
    rm -rf "$work/bootstrap"
fi
step "unpack the clean root"
mkdir -p "$root"
tar -C "$root" -xf "$cache"
mount -t proc proc "$root/proc"
mkdir -p "$root/tmp/debs"
cp "$build"/packages/*.deb "$root/tmp/debs/"
in_root() { chroot "$root" env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/tmp \
    DEBIAN_FRONTEND=noninteractive LANG=C.UTF-8 sh -c "$1"; }

step "apt-get install ./underfoot_*.deb"
in_root "cd /tmp/debs && apt-get update -qq && apt-get install -y -qq ./underfoot_*.deb" \
    > "$work/apt.log" 2>&1 || { tail -30 "$work/apt.log"; echo "FAIL: apt-get install"; exit 1; }
grep -E "^(Setting up|Unpacking) underfoot " "$work/apt.log" | head -2

step "underfoot render --all -o /tmp/x"
in_root "underfoot --version"
in_root "cd /tmp && underfoot render --all -o /tmp/x" > "$work/render.log" 2>&1 ||
    { cat "$work/render.log"; echo "FAIL: underfoot render --all in the clean root"; exit 1; }
n_presets=$(ls "$root"/usr/share/underfoot/surfaces/*.toml | wc -l)
n_out=$(ls "$root"/tmp/x/*.wav | wc -l)
tail -1 "$work/render.log"
[ "$n_out" = "$n_presets" ] || { echo "FAIL: $n_out files for $n_presets surfaces"; exit 1; }
in_root "underfoot protocol check /usr/share/underfoot/protocols/tvcg2011_exp2.toml > /dev/null"
in_root "test -f /usr/share/man/man1/underfoot-render.1" || { echo "FAIL: no man page"; exit 1; }

gui=("$build"/packages/underfoot-gui_*.deb)
if [ -f "${gui[0]}" ]; then
    step "apt-get install ./underfoot-gui_*.deb"
    in_root "cd /tmp/debs && apt-get install -y -qq ./underfoot-gui_*.deb" > "$work/apt-gui.log" 2>&1 ||
        { tail -30 "$work/apt-gui.log"; echo "FAIL: apt-get install underfoot-gui"; exit 1; }
    in_root "underfoot-gui --help" | grep -q -- --study || { echo "FAIL: underfoot-gui --help"; exit 1; }
    in_root "cd /tmp && QT_QPA_PLATFORM=offscreen XDG_RUNTIME_DIR=/tmp underfoot-gui \
        --data-dir /tmp/gui --screenshot /tmp/shots" > "$work/gui.log" 2>&1 ||
        { tail -20 "$work/gui.log"; echo "FAIL: underfoot-gui --screenshot in the clean root"; exit 1; }
    [ -f "$root/tmp/gui/demo_study.db" ] || { echo "FAIL: no demo study"; exit 1; }
    in_root "test -f /usr/share/applications/underfoot-gui.desktop && \
        test -f /usr/share/icons/hicolor/scalable/apps/underfoot.svg" ||
        { echo "FAIL: desktop entry or icon missing"; exit 1; }
    echo "underfoot-gui: $(ls "$root"/tmp/shots/*.png | wc -l) screenshots of the installed console"
else
    echo "(no underfoot-gui package: the console is not built here)"
fi
step "ok: installed in a clean Debian 12 root and rendered $n_out surfaces"
