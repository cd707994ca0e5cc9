#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The wading simulation and studies end to end through the `underfoot` program:
#  - `wade` renders deterministically from the virtual gait and from a gait file it wrote, and
#    refuses bad arguments and bad gait files with exit status 2 and the place of the error;
#  - the listening test (experiment 1) renders its clips, runs simulated participants, analyses
#    in the paper's form (Friedman, Wilcoxon with Holm) and exports participants and scales;
#  - the interactive test (experiment 2) runs with Latin-square groups and laps.
#   wading_end_to_end.sh UNDERFOOT SOURCE_DIR WORK_DIR
set -euo pipefail
underfoot="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"

expect_refusal() { # expect_refusal PATTERN COMMAND... : exit status 2 and PATTERN on stderr
  local pattern="$1"; shift
  set +e; "$@" > /dev/null 2> err.txt; local status=$?; set -e
  if [ "$status" -ne 2 ]; then echo "expected exit 2, got $status: $*"; cat err.txt; exit 1; fi
  grep -q -- "$pattern" err.txt || { echo "missing '$pattern' in:"; cat err.txt; exit 1; }
}

# wade: same seed, same bytes; a different seed, different bytes.
"$underfoot" wade --depth deep --algo v2 --cadence 63 --seconds 4 --seed 3 -o a.wav > /dev/null
"$underfoot" wade --depth deep --algo v2 --cadence 63 --seconds 4 --seed 3 -o b.wav > /dev/null
cmp a.wav b.wav
"$underfoot" wade --depth deep --algo v2 --cadence 63 --seconds 4 --seed 4 -o c.wav > /dev/null
! cmp -s a.wav c.wav
# A gait written by the virtual walker drives the model from the file.
"$underfoot" wade --write-gait gait.csv --cadence 118 --seconds 4 > /dev/null
"$underfoot" wade --depth shallow --algo v1 --gait gait.csv -o g.wav > /dev/null
test -s g.wav
# Bad input: named, located, exit 2, no output file.
expect_refusal 'no wading preset "knee"' "$underfoot" wade --depth knee -o x.wav
printf 'time_s,left_thigh_dps,right_thigh_dps,left_shank_dps,right_shank_dps\n0,1,2,3,4\n0.01,nan,2,3,4\n' > bad.csv
expect_refusal 'bad.csv:3' "$underfoot" wade --gait bad.csv -o y.wav
expect_refusal 'algo' "$underfoot" wade --algo v3 -o z.wav
test ! -e x.wav && test ! -e y.wav && test ! -e z.wav

# Experiment 1: clips, simulated participants, paper-form analysis, export.
"$underfoot" clips --protocol "$src/protocols/wading_listening.toml" -o clips1 > /dev/null
"$underfoot" clips --protocol "$src/protocols/wading_listening.toml" -o clips1 --check > /dev/null
"$underfoot" study create --protocol "$src/protocols/wading_listening.toml" --study w1.db \
  --code WAD1 --site ci --seed 16 > /dev/null
"$underfoot" session --study w1.db --simulate --participants 6 --clips clips1 \
  --rating-model "$src/protocols/simulation/wading_listening_ratings.toml" > /dev/null
"$underfoot" analyze --study w1.db --include-simulated -o w1.md > /dev/null
grep -q -i "friedman" w1.md
grep -q "p (Holm)" w1.md
"$underfoot" export --study w1.db -o out1 > /dev/null
test "$(wc -l < out1/participants.csv)" -eq 7      # header + 6 participants
grep -q -i "naturalness" out1/scales.csv
test "$(tail -n +2 out1/ratings.csv | wc -l)" -gt 0
# A listening trial replays to exactly the clip its (simulated) participant stood for: the
# simulation with --clips stores the manifest's clip (seed, length, samples' SHA-256) and replay
# renders it again through the one renderer and compares the hashes.
row=$(grep -m1 ',wade_deep_' out1/trials.csv)
participant=$(echo "$row" | cut -d, -f5)
trial=$(( $(echo "$row" | cut -d, -f8) + 1 ))   # --trial takes the 1-based number
"$underfoot" replay --study w1.db --participant "$participant" --trial "$trial" \
  -o replay.wav > replay.txt
grep -q "the samples are those the participant heard" replay.txt || { cat replay.txt; exit 1; }

# Experiment 2: Latin-square groups, silent then sounding laps, 1-7 items.
"$underfoot" study create --protocol "$src/protocols/wading_interactive.toml" --study w2.db \
  --code WAD2 --site ci --seed 9 > /dev/null
"$underfoot" session --study w2.db --simulate --participants 6 \
  --rating-model "$src/protocols/simulation/wading_interactive_ratings.toml" > /dev/null
"$underfoot" analyze --study w2.db --include-simulated -o w2.md > /dev/null
grep -q -i "friedman\|wilcoxon" w2.md
echo "wading end to end: ok"
