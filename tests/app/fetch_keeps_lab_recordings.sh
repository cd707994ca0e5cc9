#!/usr/bin/env bash
# scripts/fetch-recordings.sh deletes the fetched packages' folders and manifest.csv before it
# fetches them again; a lab's own recordings (lab-manifest.csv and the lab's folders, written by
# `underfoot recordings add`) must survive it. apt-get is replaced by one that fails, so the
# script stops at its first download, after its deletions.
# Usage: fetch_keeps_lab_recordings.sh <source dir> <work dir>
set -uo pipefail
src="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work/bin" "$work/cache/minetest/wood" "$work/cache/hall-b/gravel" ||
    exit 1
printf '#!/bin/sh\nexit 1\n' >"$work/bin/apt-get"
chmod +x "$work/bin/apt-get"
header="file,source,package,version,licence,material,recordist"
echo "fetched" >"$work/cache/minetest/wood/a.ogg"
printf '%s\nminetest/wood/a.ogg,minetest,minetest-data,1,CC0-1.0,wood,\n' "$header" \
    >"$work/cache/manifest.csv"
echo "lab" >"$work/cache/hall-b/gravel/g.wav"
printf '%s\nhall-b/gravel/g.wav,hall-b,lab,2026-12-06,CC-BY-4.0,gravel,\n' "$header" \
    >"$work/cache/lab-manifest.csv"
cp "$work/cache/lab-manifest.csv" "$work/lab-manifest.before"

PATH="$work/bin:$PATH" bash "$src/scripts/fetch-recordings.sh" "$work/cache" >"$work/out.txt" 2>&1
status=$?
fail=0
if [ "$status" = 0 ] || ! grep -q "'apt-get download minetest-data' failed" "$work/out.txt"; then
    echo "FAIL: expected the fetch to stop at its first download (status $status)"
    cat "$work/out.txt"
    fail=1
fi
if [ -e "$work/cache/minetest" ] || [ -e "$work/cache/manifest.csv" ]; then
    echo "FAIL: the fetched folders and manifest.csv were not cleared: the test no longer" \
        "reaches the script's deletions"
    fail=1
fi
if ! cmp -s "$work/lab-manifest.before" "$work/cache/lab-manifest.csv" ||
    [ "$(cat "$work/cache/hall-b/gravel/g.wav" 2>/dev/null)" != lab ]; then
    echo "FAIL: the fetch touched the lab's recordings"
    fail=1
fi
[ "$fail" = 0 ] && echo "ok: the fetch cleared its own packages and kept the lab's recordings"
exit $fail
