#!/usr/bin/env bash
# `underfoot render --grf` on a noisy force-plate file: the plate's zero is measured and taken
# off by default (a note names the file, the channel and what was taken off), and not with
# --no-grf-tare; a clean file gets no note; `grf info` shows what will be taken off. The signal
# side is tested in tests/engine/test_control_grf.cpp (GrfFile.Tare*).
# Usage: render_grf_tare.sh <underfoot> <work>
set -euo pipefail
underfoot="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work" && cd "$work"
# 4 s at 1 kHz: steps of 0.6 s (700 N half-sines) every second; in the air a deterministic
# pseudo-noise of about 3 N rms around +1 N (a linear congruential sequence, no python needed).
awk 'BEGIN {
    print "time_s,left"; s = 12345
    for (i = 0; i < 4000; i++) {
        t = (i % 1000) / 1000.0
        f = (t < 0.6) ? 700 * sin(3.141592653589793 * t / 0.6) : 0
        n = 0
        for (k = 0; k < 4; k++) { s = (1103515245 * s + 12345) % 2147483648; n += s / 2147483648 - 0.5 }
        printf "%.3f,%.3f\n", i / 1000.0, f + 1 + 3 * n * 1.732
    }
}' > noisy.csv
awk 'BEGIN { print "time_s,left"; for (i = 0; i < 4000; i++) { t = (i % 1000) / 1000.0;
    printf "%.3f,%.3f\n", i / 1000.0, (t < 0.6) ? 700 * sin(3.141592653589793 * t / 0.6) : 0 } }' \
    > clean.csv
"$underfoot" render -s gravel --grf noisy.csv --tail 0 -o noisy.wav > noisy.out 2>&1
grep -q 'noisy.csv: channel "left": force-plate zero +' noisy.out ||
    { echo "FAIL: no tare note for the noisy file"; cat noisy.out; exit 1; }
grep -q 'N taken off every sample' noisy.out || { echo "FAIL: tare note incomplete"; cat noisy.out; exit 1; }
"$underfoot" render -s gravel --grf noisy.csv --tail 0 --no-grf-tare -o raw.wav > raw.out 2>&1
if grep -q 'taken off' raw.out; then echo "FAIL: --no-grf-tare still tared"; cat raw.out; exit 1; fi
"$underfoot" render -s gravel --grf clean.csv --tail 0 -o clean.wav > clean.out 2>&1
if grep -q 'taken off' clean.out; then echo "FAIL: a clean file was tared"; cat clean.out; exit 1; fi
"$underfoot" grf info noisy.csv > info_noisy.out
grep -q 'force-plate zero +.* N off (--no-grf-tare: nothing)' info_noisy.out ||
    { echo "FAIL: grf info does not show the zero"; cat info_noisy.out; exit 1; }
"$underfoot" grf info clean.csv > info_clean.out
grep -q 'clean zero (exact 0 N in the air): nothing to take off' info_clean.out ||
    { echo "FAIL: grf info on a clean file"; cat info_clean.out; exit 1; }
echo "ok: noisy file tared ($(grep -o '[0-9.]* N taken off' noisy.out)), --no-grf-tare and a" \
    "clean file left alone, grf info shows both"
