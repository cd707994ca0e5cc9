#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Fetches recorded footsteps from Debian's archive (apt-get download, no root needed) and
# extracts them into a cache folder with a manifest, for `underfoot compare`, the realism
# listener and the tests in tests/realism (which skip, saying so, when the cache is absent).
#
#   bash scripts/fetch-recordings.sh [--large] [--unseen] [CACHE_DIR]
#
# CACHE_DIR defaults to $UNDERFOOT_RECORDINGS, else build/recordings in a source tree, else
# ~/.cache/underfoot/recordings (where an installed `underfoot compare` looks).
# By default only the four small packages are fetched (about 100 MB: minetest-data 3.6 MB,
# openarena-data 44 MB, ufoai-sound 19 MB, lugaru-data 34 MB; 90 files). --large (or
# UNDERFOOT_RECORDINGS_LARGE=1) adds the three large ones (about 1.24 GB more: nexuiz-data
# 267 MB, openclonk-data 113 MB, redeclipse-data 862 MB; 114 files in all), which the realism
# figures of docs/explanation/realism.md were measured on.
#
# Layout: CACHE_DIR/<source>/<material>/<file> and CACHE_DIR/manifest.csv with the columns
# file,source,package,version,licence,material,recordist (file relative to CACHE_DIR).
# A lab's own recordings (`underfoot recordings add`) are listed in CACHE_DIR/lab-manifest.csv,
# under source names this script does not fetch: it never touches that file or their folders.
# The audio is not shipped in the repository: it stays under its own licence (named per file in
# the manifest, from each package's copyright file) and is fetched on demand.
#
# Sources (seven independent packages, different microphones, rooms and processing; about
# 1.35 GB downloaded in all, of which redeclipse-data is 862 MB), and two unseen ones:
#   minetest-data  minetest_game's default_*_footstep*.ogg (CC0-1.0 / CC-BY-3.0 / CC-BY-SA-3.0,
#                  per file in mods/default/README.txt; freesound.org recordists)
#   openarena-data baseoa/pak0.pk3 sound/player/footsteps/ (GPL-2+): boot (hard floor),
#                  clank (metal), splash (water)
#   ufoai-sound    base/0snd.pk3 sound/footsteps/ (CC-BY-SA-3.0; sand.ogg, sand2.ogg GPL-2;
#                  per file in its copyright file): carpet, dirt, grass, gravel, sand, snow,
#                  splash (water), stone and tile (hard floor), wood. Its metal1 and metal3
#                  (GPL-2+, Nexuiz among their copyright holders in its copyright file) are
#                  Nexuiz's metalfootstep01 and 05 re-encoded (their descriptors differ by
#                  0.16-0.20 rms, any other two files by >= 1.5): taken once, from nexuiz-data.
#   lugaru-data    Sounds/FootStep{Grass,Snow,Stone}[12].ogg (CC-BY-SA-3.0, Wolfire Games)
#   nexuiz-data    data/data.pk3 sound/misc/footstep0[1-6].wav (the default step: hard floor)
#                  and metalfootstep0[1-6].wav (metal) (GPL-2+, Alientrap)
#   openclonk-data Sound.ocg (a c4group archive, unpacked with c4group from the openclonk
#                  package): Clonk/Movement/StepHard[1-5].ogg, played on the materials a
#                  clonk cannot dig (rock, granite, brick...: hard floor) (CC-BY-3.0,
#                  HerbertBoland, freesound.org sound 31962, per Sound.ocg/authors.txt).
#                  StepSoft is left out: it plays on every diggable material (earth, sand...).
#   redeclipse-data data/sounds/player/concstep*.ogg (concrete: hard floor) and swimstep*.ogg
#                  ("liquid footsteps" in redeclipse's config/sounds/player.cfg: water)
#                  (CC-BY-SA-3.0, Red Eclipse Team). footstep*.ogg, the default step, names
#                  no material and is left out.
#
#   0ad-data       (only with --unseen) public.zip audio/actor/singlesteps/fs_*.ogg: gravel,
#                  snow, sand, grass (8 each), wood (4) (CC-BY-SA-3.0, Wildfire Games, per the
#                  zip's audio/LICENSE.txt). fs_rock* are fs_gravel* again (the same Vorbis
#                  packets under another stream serial): left out. The unseen source: no preset,
#                  fit or design choice of this project has used it, and none may be chosen on
#                  it; it is there to judge the presets on recordings nobody tuned them to
#                  (docs/decisions/unseen-source.md).

#   berusky2-data  (only with --unseen) sound/sound/steps{sand,grass,snow2,snow3,steel1,
#                  stone2,wood}.wav and wstep[1-4].wav (GPL-2+, AnakreoN): the beetles' steps, chosen by the floor's
#                  material in berusky2's src/kofola/animend_functions.cpp (GetStep: pisek sand,
#                  trava grass, snih snow, zelezo steel = metal, kamen stone = hard floor, drevo
#                  wood) and in water (PlaySteps: objects of class 12, water). 22.05 kHz
#                  (wstep3 44.1 kHz), 0.65-0.96 s, two or three steps a file. The second
#                  unseen source, found by searching every file of Debian's archive (apt-file).
#
# The first four are fetched always: a failed download stops the script, naming the package.
# The next three only with --large, 0ad-data and berusky2-data only with --unseen (or
# UNDERFOOT_RECORDINGS_UNSEEN=1); UNDERFOOT_RECORDINGS_SKIP="nexuiz-data ..." then still leaves
# some of them out (each is named on the output).
# Without nexuiz-data UFO:AI's metal1 and metal3 are kept (the four-source cache, 90 files).
# The tests and `underfoot compare` read whatever the manifest lists.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
large="${UNDERFOOT_RECORDINGS_LARGE:-0}"
unseen="${UNDERFOOT_RECORDINGS_UNSEEN:-0}"
while [ $# -gt 0 ]; do
    case "$1" in
    --large) large=1 ;;
    --unseen) unseen=1 ;;
    -*)
        echo "fetch-recordings: unknown option '$1' (expected --large, --unseen or a cache folder)" >&2
        exit 2
        ;;
    *) break ;;
    esac
    shift
done
if [ -f "$root/CMakeLists.txt" ]; then
    default_cache="$root/build/recordings" # a source tree
else
    default_cache="${XDG_CACHE_HOME:-$HOME/.cache}/underfoot/recordings" # installed
fi
cache="${1:-${UNDERFOOT_RECORDINGS:-$default_cache}}"
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

keep() { # file source package version licence material recordist: into the cache, one manifest line
    mkdir -p "$cache/$2/$6"
    cp "$1" "$cache/$2/$6/"
    echo "$2/$6/$(basename "$1"),$2,$3,$4,$5,$6,$7" >>"$manifest.tmp"
}

skipped() { # package -> true when it is a large one and --large was not given, an unseen
    # one and --unseen was not given, or UNDERFOOT_RECORDINGS_SKIP names it
    if [ "$1" = 0ad-data ] || [ "$1" = berusky2-data ]; then
        [ "$unseen" = 1 ] || return 0
    else
        [ "$large" = 1 ] || return 0
    fi
    case " ${UNDERFOOT_RECORDINGS_SKIP:-} " in *" $1 "*) return 0 ;; esac
    return 1
}
if [ "$large" != 1 ]; then
    echo "fetch-recordings: the four small sources (about 100 MB); --large (or" \
        "UNDERFOOT_RECORDINGS_LARGE=1) adds nexuiz-data, openclonk-data and redeclipse-data" \
        "(about 1.24 GB more)"
fi
if [ "$unseen" = 1 ]; then
    echo "fetch-recordings: --unseen: adding 0ad-data and berusky2-data, the sources no preset" \
        "was tuned on (1.94 GB to download, about 3.3 GB of temporary space while 0ad-data's" \
        "sounds are extracted)"
fi
for p in ${UNDERFOOT_RECORDINGS_SKIP:-}; do
    case "$p" in
    nexuiz-data | openclonk-data | redeclipse-data | berusky2-data | 0ad-data) echo "fetch-recordings: leaving out $p (UNDERFOOT_RECORDINGS_SKIP)" ;;
    *)
        echo "fetch-recordings: UNDERFOOT_RECORDINGS_SKIP: '$p' is not an optional source (nexuiz-data openclonk-data redeclipse-data berusky2-data 0ad-data)" >&2
        exit 2
        ;;
    esac
done
manifest="$cache/manifest.csv"
# A source's folder from an earlier run would keep files the new manifest does not list; the
# old manifest goes too, so that a run that fails leaves no cache (the tests then skip, naming
# this script) rather than a manifest of deleted files.
rm -rf "${cache:?}"/{minetest,openarena,ufoai,lugaru,nexuiz,openclonk,redeclipse,berusky2,0ad} "$manifest"
echo "file,source,package,version,licence,material,recordist" >"$manifest.tmp"

# ---- minetest-data -------------------------------------------------------------------------
deb="$(download minetest-data)"
ver="$(dpkg-deb -f "$deb" Version)"
dpkg-deb -x "$deb" "$work/minetest"
snd="$work/minetest/usr/share/games/minetest/games/minetest_game/mods/default/sounds"
# material  file-prefix  licence  recordist (mods/default/README.txt)
while read -r material prefix licence recordist; do
    for f in "$snd"/default_"${prefix}"_footstep*.ogg; do
        [ -f "$f" ] || continue
        keep "$f" minetest minetest-data "$ver" "$licence" "$material" "$recordist"
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
    for f in "$work"/oa/sound/player/footsteps/"$prefix"[0-9].wav; do
        [ -f "$f" ] || continue
        keep "$f" openarena openarena-data "$ver" GPL-2+ "$material" "OpenArena team"
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
    for name in ${files//,/ }; do
        f="$work/ufo/sound/footsteps/$name.ogg"
        [ -f "$f" ] || continue
        keep "$f" ufoai ufoai-sound "$ver" "$licence" "$material" "${recordist//_/ }"
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
LIST
if skipped nexuiz-data; then # otherwise they come from nexuiz-data (metalfootstep01 and 05)
    for name in metal1 metal3; do
        keep "$work/ufo/sound/footsteps/$name.ogg" ufoai ufoai-sound "$ver" GPL-2+ metal "UFO:AI team (Nexuiz GPL data)"
    done
fi
cp "$work/ufoai/usr/share/doc/ufoai-sound/copyright" "$cache/licences/ufoai-sound.copyright"

# ---- lugaru-data ---------------------------------------------------------------------------
deb="$(download lugaru-data)"
ver="$(dpkg-deb -f "$deb" Version)"
dpkg-deb -x "$deb" "$work/lugaru"
while read -r material prefix; do
    for f in "$work"/lugaru/usr/share/games/lugaru/Sounds/FootStep"$prefix"[0-9].ogg; do
        [ -f "$f" ] || continue
        keep "$f" lugaru lugaru-data "$ver" CC-BY-SA-3.0 "$material" "Wolfire Games"
    done
done <<'LIST'
grass Grass
snow Snow
hard Stone
LIST
cp "$work/lugaru/usr/share/doc/lugaru-data/copyright" "$cache/licences/lugaru-data.copyright"

# The later sources: one .deb at a time, removed after use (redeclipse-data is 862 MB); only the
# files used are extracted.
extract() { # deb dest paths... : only those paths (tar wildcards) of the package
    local deb="$1" dest="$2"
    shift 2
    mkdir -p "$dest"
    dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$dest" --wildcards "$@"
}

# ---- nexuiz-data ---------------------------------------------------------------------------
if ! skipped nexuiz-data; then
    deb="$(download nexuiz-data)"
    ver="$(dpkg-deb -f "$deb" Version)"
    extract "$deb" "$work/nexuiz" ./usr/share/games/nexuiz/data/data.pk3 ./usr/share/doc/nexuiz-data/copyright
    rm -f "$deb"
    pk3="$work/nexuiz/usr/share/games/nexuiz/data/data.pk3"
    python3 - "$pk3" "$work/nx" <<'PY' 2>/dev/null || unzip -q -o "$pk3" 'sound/misc/*footstep0*.wav' -d "$work/nx"
import re, sys, zipfile
z = zipfile.ZipFile(sys.argv[1])
for n in z.namelist():
    if re.fullmatch(r"sound/misc/(metal)?footstep0[0-9]\.wav", n):
        z.extract(n, sys.argv[2])
PY
    rm -f "$pk3"
    while read -r material prefix; do
        for f in "$work"/nx/sound/misc/"$prefix"0[1-6].wav; do
            [ -f "$f" ] || continue
            keep "$f" nexuiz nexuiz-data "$ver" GPL-2+ "$material" "Alientrap (Nexuiz)"
        done
    done <<'LIST'
hard footstep
metal metalfootstep
LIST
    cp "$work/nexuiz/usr/share/doc/nexuiz-data/copyright" "$cache/licences/nexuiz-data.copyright"
fi

# ---- openclonk-data ------------------------------------------------------------------------
if ! skipped openclonk-data; then
    # c4group (openclonk's archive tool, in the openclonk package: needs only libz and
    # libstdc++) unpacks Sound.ocg; the package is extracted, not installed.
    deb="$(download openclonk)"
    extract "$deb" "$work/openclonk-bin" ./usr/bin/c4group
    rm -f "$deb"
    deb="$(download openclonk-data)"
    ver="$(dpkg-deb -f "$deb" Version)"
    extract "$deb" "$work/openclonk" ./usr/share/games/openclonk/Sound.ocg ./usr/share/doc/openclonk-data/copyright
    rm -f "$deb"
    (cd "$work/openclonk/usr/share/games/openclonk" && "$work/openclonk-bin/usr/bin/c4group" Sound.ocg -x >/dev/null) || {
        echo "fetch-recordings: openclonk's c4group could not unpack Sound.ocg of openclonk-data" >&2
        exit 1
    }
    snd="$work/openclonk/usr/share/games/openclonk/Sound.ocg"
    for f in "$snd"/Clonk.ocg/Movement.ocg/StepHard[1-5].ogg; do
        [ -f "$f" ] || continue
        keep "$f" openclonk openclonk-data "$ver" CC-BY-3.0 hard "HerbertBoland (freesound.org)"
    done
    cp "$work/openclonk/usr/share/doc/openclonk-data/copyright" "$cache/licences/openclonk-data.copyright"
    cp "$snd/authors.txt" "$cache/licences/openclonk-data-Sound-authors.txt"
    rm -rf "$work/openclonk" "$work/openclonk-bin"
fi

# ---- redeclipse-data -----------------------------------------------------------------------
if ! skipped redeclipse-data; then
    deb="$(download redeclipse-data)"
    ver="$(dpkg-deb -f "$deb" Version)"
    rd=./usr/share/games/redeclipse/data/sounds
    extract "$deb" "$work/redeclipse" "$rd/player/concstep*.ogg" "$rd/player/swimstep*.ogg" \
        "$rd/readme.txt" ./usr/share/doc/redeclipse-data/copyright
    rm -f "$deb"
    while read -r material prefix; do
        for f in "$work/redeclipse/$rd/player/$prefix"*.ogg; do
            [ -f "$f" ] || continue
            keep "$f" redeclipse redeclipse-data "$ver" CC-BY-SA-3.0 "$material" "Red Eclipse Team"
        done
    done <<'LIST'
hard concstep
water swimstep
LIST
    cp "$work/redeclipse/usr/share/doc/redeclipse-data/copyright" "$cache/licences/redeclipse-data.copyright"
    cp "$work/redeclipse/$rd/readme.txt" "$cache/licences/redeclipse-data-sounds-readme.txt"
fi

# ---- berusky2-data -------------------------------------------------------------------------
if ! skipped berusky2-data; then
    deb="$(download berusky2-data)"
    ver="$(dpkg-deb -f "$deb" Version)"
    bs=./usr/share/games/berusky2/sound/sound
    extract "$deb" "$work/berusky2" "$bs/steps*.wav" "$bs/wstep*.wav" \
        ./usr/share/doc/berusky2-data/copyright
    rm -f "$deb"
    while read -r material names; do
        for n in $names; do
            f="$work/berusky2/$bs/$n.wav"
            [ -f "$f" ] || continue
            keep "$f" berusky2 berusky2-data "$ver" GPL-2+ "$material" AnakreoN
        done
    done <<'LIST'
sand stepsand
grass stepsgrass
snow stepsnow2 stepsnow3
metal stepssteel1
hard stepsstone2
wood stepswood
water wstep1 wstep2 wstep3 wstep4
LIST
    cp "$work/berusky2/usr/share/doc/berusky2-data/copyright" "$cache/licences/berusky2-data.copyright"
    rm -rf "$work/berusky2"
fi

# ---- 0ad-data ------------------------------------------------------------------------------
if ! skipped 0ad-data; then
    # public.zip (3.3 GB inside the 1.38 GB package) holds the game's data; only its single
    # footsteps are kept, and fs_rock* (fs_gravel* again) is left out.
    deb="$(download 0ad-data)"
    ver="$(dpkg-deb -f "$deb" Version)"
    zad=./usr/share/games/0ad/mods/public
    extract "$deb" "$work/0ad" "$zad/public.zip" ./usr/share/doc/0ad-data/copyright
    rm -f "$deb"
    python3 - "$work/0ad/$zad/public.zip" "$work/zad" <<'PY' ||
import re, sys, zipfile
z = zipfile.ZipFile(sys.argv[1])
for n in z.namelist():
    if re.fullmatch(r"audio/actor/singlesteps/fs_[a-z_0-9]+\.ogg", n) or n == "audio/LICENSE.txt":
        z.extract(n, sys.argv[2])
PY
        unzip -q -o "$work/0ad/$zad/public.zip" 'audio/actor/singlesteps/fs_*.ogg' audio/LICENSE.txt -d "$work/zad"
    rm -f "$work/0ad/$zad/public.zip"
    while read -r material prefix; do
        for f in "$work/zad/audio/actor/singlesteps/fs_$prefix"[0-9]*.ogg; do
            [ -f "$f" ] || continue
            keep "$f" 0ad 0ad-data "$ver" CC-BY-SA-3.0 "$material" "Wildfire Games (0 A.D.)"
        done
    done <<'LIST'
gravel gravel
snow snow_
sand sand
grass grass
wood wood
LIST
    cp "$work/0ad/usr/share/doc/0ad-data/copyright" "$cache/licences/0ad-data.copyright"
    cp "$work/zad/audio/LICENSE.txt" "$cache/licences/0ad-data-audio-LICENSE.txt"
    rm -rf "$work/0ad" "$work/zad"
fi

mv "$manifest.tmp" "$manifest"
n=$(($(wc -l <"$manifest") - 1))
nsrc=$(tail -n +2 "$manifest" | cut -d, -f2 | sort -u | wc -l)
echo "fetch-recordings: $n recorded footstep files from $nsrc sources in $cache (manifest: $manifest)"
