#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Replay (and analysis of a study store) end to end through the `underfoot` program: a study whose stimuli are driven by the
# virtual walker is run (simulated participant), then each trial is re-rendered from the store.
# A replay must be identical to itself and to `underfoot render` with the stored seed; a trial
# answered without sound (data entry) must be refused with a clear message.
#   replay_end_to_end.sh UNDERFOOT SOURCE_DIR WORK_DIR
set -euo pipefail
underfoot="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"

printf 'stimulus,BS,GL,WD,DK\nGL,0,5,0,0\nWR,0,0,5,0\nBS,5,0,0,0\n' > confusion.csv
"$underfoot" study create --study walk.db --protocol "$src/tests/app/replay_walk.toml" --code RP --site ci --seed 5 > /dev/null
"$underfoot" session --study walk.db --simulate --participants 1 --confusion confusion.csv > /dev/null
"$underfoot" export --study walk.db -o out > /dev/null

# The gravel trial: participant, trial index and render seed from the export.
row=$(grep -m1 ',GL,gravel,' out/trials.csv)
participant=$(echo "$row" | cut -d, -f5)
trial=$(( $(echo "$row" | cut -d, -f8) + 1 ))   # --trial takes the 1-based number
seed=$(echo "$row" | cut -d, -f17)
"$underfoot" replay --study walk.db --participant "$participant" --trial "$trial" -o a.wav > /dev/null
"$underfoot" replay --study walk.db --participant "$participant" --trial "$trial" -o b.wav > /dev/null
cmp a.wav b.wav
"$underfoot" render --surface gravel --walker cadence=100,mass=70 --seconds 10 --seed "$seed" \
  --tail 1 --format float -q -o rendered.wav
cmp a.wav rendered.wav

# The study store analyses directly, columns in the protocol's answer order.
"$underfoot" analyze --study walk.db --format markdown 2> left_out.txt > analysis.md
grep -q "1 simulated participant left out" left_out.txt
"$underfoot" analyze --study walk.db --include-simulated --format markdown > analysis.md
grep -q "| Stimulus | BS | GL | WD | DK | n |" analysis.md

# Every trial replays (reverb and soundscape stimuli included).
for t in 1 2 3; do
  "$underfoot" replay --study walk.db --participant "$participant" --trial "$t" -o "t$t.wav" > "t$t.txt"
  test -s "t$t.wav"
done
grep -q "beach_summer" t*.txt

# A microphone-driven protocol (TVCG 2011 exp. 1). A simulated participant's feet are the
# virtual walker for the protocol's trial time (50 s), recorded as the trial's control stream:
# its trials replay, identical to `underfoot render` with the stored seed.
"$underfoot" study create --study mic.db --protocol "$src/protocols/tvcg2011_exp1.toml" --code M --site ci --seed 1 > /dev/null
"$underfoot" study register --study mic.db --participant P1 > /dev/null
"$underfoot" session --study mic.db --simulate --participants 1 > /dev/null
"$underfoot" export --study mic.db -o mic > /dev/null
row=$(grep -m1 ',GL,gravel,' mic/trials.csv)
mp=$(echo "$row" | cut -d, -f5)
mtrial=$(( $(echo "$row" | cut -d, -f8) + 1 ))
mseed=$(echo "$row" | cut -d, -f17)
"$underfoot" replay --study mic.db --participant "$mp" --trial "$mtrial" -o m.wav > m.txt
grep -q "simulated participant's virtual walker" m.txt
walker=$(grep -o "virtual walker [^ ]*" m.txt | sed 's/virtual walker //; s/,$//')
"$underfoot" render --surface gravel --walker "$walker" --seconds 50 --seed "$mseed" \
  --tail 1 --format float -q -o m_rendered.wav
cmp m.wav m_rendered.wav
# A person's trial answered without sound (data entry): refused, exit status 2, with the reason.
printf '\n\na\n\nquit\n' | "$underfoot" session --study mic.db --participant P1 > p1.txt || true
grep -q "NO SOUND" p1.txt
set +e
"$underfoot" replay --study mic.db --participant P1 --trial 1 -o x.wav 2> refused.txt
status=$?
set -e
test "$status" -eq 2
grep -q "without sound (data entry" refused.txt
test ! -e x.wav
echo "replay end to end: ok"
