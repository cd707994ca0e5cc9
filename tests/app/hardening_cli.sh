#!/usr/bin/env bash
# Regressions through the `underfoot` program: each input used to crash, hang or
# allocate without bound; each must now end normally or be refused with a message naming the
# input. Usage: hardening_cli.sh <underfoot> <source dir> <work dir>
set -uo pipefail
underfoot="$1"
src="$2"
work="$3"
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fail=0
check() { # check NAME EXPECTED_STATUS(ok|refused) PATTERN -- command...
    local name="$1" want="$2" pattern="$3"
    shift 4
    timeout 120 "$@" > "$name.out" 2>&1
    local st=$?
    if [ "$st" -ge 124 ]; then
        echo "FAIL $name: status $st (crash, sanitizer report or timeout)"; cat "$name.out" | tail -30; fail=1; return
    fi
    if [ "$want" = ok ] && [ "$st" != 0 ]; then
        echo "FAIL $name: status $st, expected success"; tail -30 "$name.out"; fail=1; return
    fi
    if [ "$want" = refused ] && [ "$st" = 0 ]; then
        echo "FAIL $name: accepted, expected a refusal"; tail -30 "$name.out"; fail=1; return
    fi
    if [ -n "$pattern" ] && ! grep -q -- "$pattern" "$name.out"; then
        echo "FAIL $name: output lacks \"$pattern\""; tail -30 "$name.out"; fail=1; return
    fi
    echo "ok   $name"
}

# 1. `underfoot surfaces -v` read freed memory (range-for over a temporary's parameters).
check surfaces_verbose ok "layer" -- "$underfoot" surfaces -v

# 2. A study whose user_version is not ours indexed the migrations at -1.
"$underfoot" study create --study damaged.db --protocol "$src/protocols/tvcg2011_exp1.toml" \
    --code D1 --site lab --seed 1 > /dev/null || { echo "FAIL: study create"; exit 1; }
sqlite3 damaged.db "PRAGMA user_version = -1" || exit 1
check export_damaged refused "damaged.db: not an Underfoot study (schema version -1" -- \
    "$underfoot" export --study damaged.db -o out/

# 3. A GRF WAV claiming 1 Hz (and one claiming a 4 GB data chunk).
# Little-endian fields written with printf (no python needed on a fresh machine).
le() { # le VALUE BYTES
    local v=$1 i
    for ((i = 0; i < $2; i++)); do printf "\\x$(printf %02x $(((v >> (8 * i)) & 255)))"; done
}
wav() { # wav FILE RATE FRAMES CLAIMED_DATA_BYTES  (16-bit PCM mono)
    {
        printf 'RIFF'; le $((36 + $4)) 4; printf 'WAVEfmt '; le 16 4; le 1 2; le 1 2
        le "$2" 4; le $(($2 * 2)) 4; le 2 2; le 16 2; printf 'data'; le "$4" 4
        for ((i = 0; i < $3; i++)); do le $(((i * 97) % 3000)) 2; done
    } > "$1"
}
wav one_hz.wav 1 400 800
wav huge_claim.wav 1000 400 $((0xfffffff0))
check grf_one_hz refused "one_hz.wav: sample rate 1 Hz" -- \
    "$underfoot" render --surface wood --grf one_hz.wav -o one_hz_out.wav
check grf_huge_claim ok "" -- "$underfoot" render --surface wood --grf huge_claim.wav -o huge_out.wav -q

# 4. `underfoot stats` names line and column of a parse error, and the key of a wrong type.
check stats_parse refused "line 2, column 12" -- bash -c "printf '{\"table\":\n [[8, 12], x]}' | '$underfoot' stats chisq"
check stats_type refused "'table\[1\]\[0\]'" -- bash -c "echo '{\"table\": [[8, 12], [\"a\", 2]]}' | '$underfoot' stats chisq"

# 5. `compare --figures` renders every seed of --seeds: a lone --seed would be ignored silently,
#    and --seeds means nothing without --figures.
check compare_figures_seed refused "give --seeds N" -- "$underfoot" compare --figures --seed 5
check compare_seeds_without_figures refused "--seeds goes with --figures" -- \
    "$underfoot" compare --all --seeds 3
check compare_markdown_all refused "--markdown goes with --listener or --figures" -- \
    "$underfoot" compare --all --markdown

# 6. `recordings add|list|remove`: a lab's recordings go into a cache as their own source; bad
#    names, materials and files are refused naming them, and leave the cache as it was.
"$underfoot" render --surface gravel --seconds 2 -o lab_gravel.wav -q
"$underfoot" render --surface wood --seconds 2 -o lab_wood.wav -q
printf 'not audio' > lab_notes.wav
check recordings_list_none refused "lab_cache/manifest.csv: no recordings manifest" -- \
    "$underfoot" recordings list --recordings lab_cache
check recordings_add ok "note: hall-b has one material" -- "$underfoot" recordings add --source hall-b \
    --material gravel --licence CC-BY-4.0 --recordings lab_cache lab_gravel.wav
check recordings_add_wood ok "hall-b/wood/lab_wood.wav" -- "$underfoot" recordings add \
    --source hall-b --material wood --licence CC-BY-4.0 --recordings lab_cache lab_wood.wav
check recordings_list ok "hall-b         2  gravel 1, wood 1  \[lab" -- \
    "$underfoot" recordings list --recordings lab_cache
cp lab_cache/lab-manifest.csv lab_manifest_before.csv
check recordings_fetched_name refused '"ufoai" is a package scripts/fetch-recordings.sh' -- \
    "$underfoot" recordings add --source ufoai --material gravel --licence x \
    --recordings lab_cache lab_gravel.wav
check recordings_material refused 'unknown material "stone"' -- "$underfoot" recordings add \
    --source hall-c --material stone --licence x --recordings lab_cache lab_gravel.wav
check recordings_not_audio refused "lab_notes.wav" -- "$underfoot" recordings add \
    --source hall-c --material gravel --licence x --recordings lab_cache lab_gravel.wav lab_notes.wav
check recordings_twice refused "hall-b/gravel/lab_gravel.wav is already in the cache" -- \
    "$underfoot" recordings add --source hall-b --material gravel --licence x \
    --recordings lab_cache lab_gravel.wav
if cmp -s lab_manifest_before.csv lab_cache/lab-manifest.csv && [ ! -e lab_cache/hall-c ]; then
    echo "ok   recordings_refusals_leave_the_cache"
else
    echo "FAIL recordings_refusals_leave_the_cache: a refused add changed the cache"; fail=1
fi
check recordings_remove ok "removed source hall-b (2 files)" -- \
    "$underfoot" recordings remove --source hall-b --recordings lab_cache
check recordings_remove_again refused 'no lab source "hall-b" (it lists: none)' -- \
    "$underfoot" recordings remove --source hall-b --recordings lab_cache

exit $fail
