#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Fetches recorded footsteps from Debian's archive (apt-get download, no root needed) and
# extracts them into a cache folder with a manifest, for `underfoot compare`, the realism
# listener and the tests in tests/realism (which skip, saying so, when the cache is absent).
#
#   bash scripts/fetch-recordings.sh [CACHE_DIR]     # default: build/recordings
#
# Layout: CACHE_DIR/<source>/<material>/<file> and CACHE_DIR/manifest.csv with the columns
# file,source,package,version,licence,material,recordist (file relative to CACHE_DIR).
# The audio is not shipped in the repository: it stays under its own licence (named per file in
# the manifest, from each package's copyright file) and is fetched on demand.
#
# Sources (four independent packages, different microphones, rooms and processing; about
# 110 MB downloaded in all):
#   minetest-data  minetest_game's default_*_footstep*.ogg (CC0-1.0 / CC-BY-3.0 / CC-BY-SA-3.0,
#                  per file in mods/default/README.txt; freesound.org recordists)
#   openarena-data baseoa/pak0.pk3 sound/player/footsteps/ (GPL-2+): boot (hard floor),
#                  clank (metal), splash (water)
#   ufoai-sound    base/0snd.pk3 sound/footsteps/ (CC-BY-SA-3.0; sand.ogg, sand2.ogg GPL-2;
#                  metal1, metal3 GPL-2+; per file in its copyright file): carpet, dirt, grass,
#                  gravel, sand, snow, splash (water), stone and tile (hard floor), wood, metal
#   lugaru-data    Sounds/FootStep{Grass,Snow,Stone}[12].ogg (CC-BY-SA-3.0, Wolfire Games)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cache="${1:-${UNDERFOOT_RECORDINGS:-$root/build/recordings}}"
mkdir -p "$cache"
cache="$(cd "$cache" && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

download() { # package -> path of the .deb in $work
    (cd "$work" && apt-get download "$1" >/dev/null 2>&1) || {
        echo "fetch-recordings: 'apt-get download $1' failed (is Debian's archive reachable and 'apt-get update' done?)" >&2
        return 1
    }
    ls "$work"/"$1"_*.deb
}

manifest="$cache/manifest.csv"
echo "file,source,package,version,licence,material,recordist" >"$manifest.tmp"

# ---- minetest-data -------------------------------------------------------------------------
deb="$(download minetest-data)"
ver="$(dpkg-deb -f "$deb" Version)"
dpkg-deb -x "$deb" "$work/minetest"
snd="$work/minetest/usr/share/games/minetest/games/minetest_game/mods/default/sounds"
# material  file-prefix  licence  recordist (mods/default/README.txt)
while read -r material prefix licence recordist; do
    mkdir -p "$cache/minetest/$material"
    for f in "$snd"/default_"${prefix}"_footstep*.ogg; do
        [ -f "$f" ] || continue
        cp "$f" "$cache/minetest/$material/"
        echo "minetest/$material/$(basename "$f"),minetest,minetest-data,$ver,$licence,$material,$recordist" >>"$manifest.tmp"
    done
done <<'LIST'
wood wood CC-BY-SA-3.0 celeron55/minetest
gravel gravel CC-BY-SA-3.0 celeron55/minetest
dirt dirt CC-BY-SA-3.0 celeron55/minetest
grass grass CC-BY-SA-3.0 celeron55/minetest
metal metal CC0-1.0 mypantsfelldown
water water CC-BY-3.0 AGFX
snow snow CC0-1.0 Ryding
hard hard CC-BY-3.0 Erdie
sand sand CC0-1.0 worthahep88
ice ice CC-BY-3.0 InspectorJ
LIST
mkdir -p "$cache/licences"
cp "$work/minetest/usr/share/doc/minetest-data/copyright" "$cache/licences/minetest-data.copyright"
cp "$snd/../README.txt" "$cache/licences/minetest_game-default-README.txt"

# ---- openarena-data ------------------------------------------------------------------------
deb="$(download openarena-data)"
ver="$(dpkg-deb -f "$deb" Version)"
dpkg-deb -x "$deb" "$work/openarena"
pk3="$work/openarena/usr/share/games/openarena/baseoa/pak0.pk3"
python3 - "$pk3" "$work/oa" <<'PY' 2>/dev/null || unzip -q -o "$pk3" 'sound/player/footsteps/*' -d "$work/oa"
import sys, zipfile
z = zipfile.ZipFile(sys.argv[1])
for n in z.namelist():
    if n.startswith("sound/player/footsteps/"):
        z.extract(n, sys.argv[2])
PY
while read -r material prefix; do
    mkdir -p "$cache/openarena/$material"
    for f in "$work"/oa/sound/player/footsteps/"$prefix"[0-9].wav; do
        [ -f "$f" ] || continue
        cp "$f" "$cache/openarena/$material/"
        echo "openarena/$material/$(basename "$f"),openarena,openarena-data,$ver,GPL-2+,$material,OpenArena team" >>"$manifest.tmp"
    done
done <<'LIST'
hard boot
metal clank
water splash
LIST
cp "$work/openarena/usr/share/doc/openarena-data/copyright" "$cache/licences/openarena-data.copyright"

# ---- ufoai-sound ---------------------------------------------------------------------------
deb="$(download ufoai-sound)"
ver="$(dpkg-deb -f "$deb" Version)"
dpkg-deb -x "$deb" "$work/ufoai"
python3 - "$work/ufoai/usr/share/games/ufoai/base/0snd.pk3" "$work/ufo" <<'PY' 2>/dev/null ||
import sys, zipfile
z = zipfile.ZipFile(sys.argv[1])
for n in z.namelist():
    if n.startswith("sound/footsteps/"):
        z.extract(n, sys.argv[2])
PY
    unzip -q -o "$work/ufoai/usr/share/games/ufoai/base/0snd.pk3" 'sound/footsteps/*' -d "$work/ufo"
# material  files  licence (debian/copyright of ufoai-sound)  recordist
while read -r material files licence recordist; do
    mkdir -p "$cache/ufoai/$material"
    for name in ${files//,/ }; do
        f="$work/ufo/sound/footsteps/$name.ogg"
        [ -f "$f" ] || continue
        cp "$f" "$cache/ufoai/$material/"
        echo "ufoai/$material/$name.ogg,ufoai,ufoai-sound,$ver,$licence,$material,${recordist//_/ }" >>"$manifest.tmp"
    done
done <<'LIST'
carpet carpet1,carpet2,carpet3,carpet4 CC-BY-SA-3.0 UFO:AI_team
dirt dirt1,dirt2,dirt3,dirt4 CC-BY-SA-3.0 UFO:AI_team
grass grass1,grass2,grass3,grass4 CC-BY-SA-3.0 UFO:AI_team
gravel gravel1,gravel2,gravel3,gravel4 CC-BY-SA-3.0 UFO:AI_team
sand sand1 CC-BY-SA-3.0 UFO:AI_team
sand sand,sand2 GPL-2 UFO:AI_team_(OpenArena/Nexuiz_GPL_data)
snow snow1,snow2,snow3,snow4 CC-BY-SA-3.0 UFO:AI_team
water splash1,splash2,splash3,splash4 CC-BY-SA-3.0 UFO:AI_team
hard stone1,stone2,stone3,stone4,tile1,tile2,tile3,tile4 CC-BY-SA-3.0 UFO:AI_team
wood wood1,wood2,wood3,wood4 CC-BY-SA-3.0 UFO:AI_team
metal metal1,metal3 GPL-2+ UFO:AI_team_(Nexuiz_GPL_data)
LIST
cp "$work/ufoai/usr/share/doc/ufoai-sound/copyright" "$cache/licences/ufoai-sound.copyright"

# ---- lugaru-data ---------------------------------------------------------------------------
deb="$(download lugaru-data)"
ver="$(dpkg-deb -f "$deb" Version)"
dpkg-deb -x "$deb" "$work/lugaru"
while read -r material prefix; do
    mkdir -p "$cache/lugaru/$material"
    for f in "$work"/lugaru/usr/share/games/lugaru/Sounds/FootStep"$prefix"[0-9].ogg; do
        [ -f "$f" ] || continue
        cp "$f" "$cache/lugaru/$material/"
        echo "lugaru/$material/$(basename "$f"),lugaru,lugaru-data,$ver,CC-BY-SA-3.0,$material,Wolfire Games" >>"$manifest.tmp"
    done
done <<'LIST'
grass Grass
snow Snow
hard Stone
LIST
cp "$work/lugaru/usr/share/doc/lugaru-data/copyright" "$cache/licences/lugaru-data.copyright"

mv "$manifest.tmp" "$manifest"
n=$(($(wc -l <"$manifest") - 1))
echo "fetch-recordings: $n recorded footstep files in $cache (manifest: $manifest)"
