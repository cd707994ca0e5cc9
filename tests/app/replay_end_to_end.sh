#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Replay (and analysis of a study store) end to end through the `underfoot` program: a study whose stimuli are driven by the
# virtual walker is run (simulated participant), then each trial is re-rendered from the store.
# A replay must be identical to itself and to `underfoot render` with the stored seed; a trial
# driven by a live sensor with no GRF recording must be refused with a clear message.
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
grep -q "1 simulated participant(s) left out" left_out.txt
"$underfoot" analyze --study walk.db --include-simulated --format markdown > analysis.md
grep -q "| Stimulus | BS | GL | WD | DK | n |" analysis.md

# Every trial replays (reverb and soundscape stimuli included).
for t in 1 2 3; do
  "$underfoot" replay --study walk.db --participant "$participant" --trial "$t" -o "t$t.wav" > "t$t.txt"
  test -s "t$t.wav"
done
grep -q "beach_summer" t*.txt

# Sensor-driven study without GRF recordings: refused, exit status 2, with the reason.
"$underfoot" study create --study mic.db --protocol "$src/protocols/tvcg2011_exp2.toml" --code M --site ci --seed 1 > /dev/null
"$underfoot" session --study mic.db --simulate --participants 1 \
  --confusion "none=$src/tests/experiment/data/tvcg2011_exp2_cond1_no_soundscape_confusion.csv" \
  --confusion "coherent=$src/tests/experiment/data/tvcg2011_exp2_cond2_coherent_confusion.csv" \
  --confusion "incoherent=$src/tests/experiment/data/tvcg2011_exp2_cond3_incoherent_confusion.csv" > /dev/null
"$underfoot" export --study mic.db -o mic > /dev/null
mp=$(sed -n 2p mic/trials.csv | cut -d, -f5)
set +e
"$underfoot" replay --study mic.db --participant "$mp" --trial 1 -o x.wav 2> refused.txt
status=$?
set -e
test "$status" -eq 2
grep -q "no GRF recording is stored" refused.txt
test ! -e x.wav
echo "replay end to end: ok"
