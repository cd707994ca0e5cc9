#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# A live session from the terminal through real components: a JACK server with the dummy driver
# stands in for the sound card, a socat pseudo-terminal pair and `underfoot sensors simulate`
# for the FSR shoes.
#  1. Walker stimuli play through the device; each trial's GRF recording, meters and audio
#     figures are stored, and `replay` re-renders at the live block size (64).
#  2. FSR stimuli: the shoes stop writing mid-trial; the session pauses with the reason, stores
#     nothing for the broken presentation, resumes when the shoes are back, presents the trial
#     again and stores it with its sensor log.
#   live_session_end_to_end.sh UNDERFOOT SOURCE_DIR WORK_DIR     (exit 77: skipped)
set -euo pipefail
underfoot="$1"; src="$2"; work="$3"
for tool in jackd socat; do
  command -v "$tool" > /dev/null || { echo "skipped: $tool is not installed"; exit 77; }
done
rm -rf "$work"; mkdir -p "$work"; cd "$work"

export JACK_NO_START_SERVER=1
export JACK_DEFAULT_SERVER="underfoot_cli_$$"
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2> /dev/null || true; done; wait 2> /dev/null || true; }
trap cleanup EXIT
# A failing step says which one it was and shows the outputs so far (set -e alone exits silently).
trap 'echo "failed at line $LINENO: $BASH_COMMAND"; for f in *.txt jackd.log; do [ -e "$f" ] && { echo "--- $f"; tail -n 15 "$f"; }; done' ERR
jackd --no-realtime -n "$JACK_DEFAULT_SERVER" -d dummy -r 48000 -p 64 -C 4 -P 6 > jackd.log 2>&1 &
pids+=($!)
for _ in $(seq 50); do jack_lsp > /dev/null 2>&1 && break; sleep 0.1; done
jack_lsp > /dev/null 2>&1 || { echo "jackd did not start"; cat jackd.log; exit 1; }
# The ports exist, but on a loaded machine RtAudio's probe of a new server can still fail for a
# moment (its client cannot open and the device list comes back empty). Ready means that our own
# device list shows "system", within 10 s.
for _ in $(seq 100); do
  "$underfoot" devices --api jack 2> /dev/null | grep -q '"system"' && break
  sleep 0.1
done

"$underfoot" devices --api jack --save audio.toml > /dev/null

# 1. Walker stimuli through the device.
"$underfoot" study create --study walk.db --protocol "$src/tests/app/replay_walk.toml" \
  --code LW --site ci --seed 3 > /dev/null
"$underfoot" study register --study walk.db --participant P1 > /dev/null
( echo; for answer in b b b; do echo; sleep 0.4; echo "$answer"; done ) |
  "$underfoot" session --study walk.db --participant P1 --live --settings audio.toml > walk.txt
grep -q "live audio: jack" walk.txt
grep -q "session complete: 3 trials answered" walk.txt
test "$(ls recordings/grf_*.wav | wc -l)" -eq 3
test "$(ls recordings/grf_*.wav.meters.toml | wc -l)" -eq 3
"$underfoot" export --study walk.db -o out > /dev/null
# audio.csv: sample_rate_hz (8) = 48000, block_size (9) = 64, frames (10) > 0 on every row.
test "$(tail -n +2 out/audio.csv | awk -F, '$8 == 48000 && $9 == 64 && $10 > 0' | wc -l)" -eq 3
"$underfoot" replay --study walk.db --participant P1 --trial 2 -o t1.wav > replay.txt
grep -q "block 64" replay.txt

# 2. FSR shoes on a pseudo-terminal pair; they stop writing during the trial.
socat pty,raw,echo=0,link="$work/shoes" pty,raw,echo=0,link="$work/app" > socat.log 2>&1 &
pids+=($!)
for _ in $(seq 50); do [ -e "$work/app" ] && [ -e "$work/shoes" ] && break; sleep 0.1; done
"$underfoot" study create --study fsr.db --protocol "$src/tests/app/fsr_live.toml" \
  --code LF --site ci --seed 4 > /dev/null
"$underfoot" study register --study fsr.db --participant P1 > /dev/null
"$underfoot" sensors simulate --serial "$work/shoes" --seconds 3 > sim1.txt 2>&1 &
pids+=($!)
sleep 1
(
  echo             # briefing done
  echo             # start the stimulus: the shoes are walking
  sleep 4          # the simulator stops after 3 s: silence, a fault within a second
  echo a           # the answer is not stored: the session pauses instead
  "$underfoot" sensors simulate --serial "$work/shoes" --seconds 30 > sim2.txt 2>&1 &
  echo $! > sim2.pid
  sleep 3
  echo             # the shoes are back: resume
  echo             # the trial again
  sleep 1
  echo a
) | "$underfoot" session --study fsr.db --participant P1 --live --settings audio.toml \
      --serial "$work/app" > fsr.txt 2>&1 || { cat fsr.txt; exit 1; }
kill "$(cat sim2.pid)" 2> /dev/null || true
grep -q "FSR shoes on" fsr.txt
grep -q "PAUSED — FSR shoes" fsr.txt || { cat fsr.txt; exit 1; }
grep -q "session complete: 1 trial answered" fsr.txt
"$underfoot" export --study fsr.db -o fout > /dev/null
# The stored trial: answered, one interruption, a sensor log that exists.
row=$(sed -n 2p fout/audio.csv)
test "$(echo "$row" | cut -d, -f6)" = "1"
test "$(echo "$row" | cut -d, -f18)" = "1"
log=$(echo "$row" | cut -d, -f17)
test -n "$log" && test -s "$log"

# 3. `clips --live` plays the listening-test clips through the device.
printf '[protocol]\nid = "cl"\nversion = 1\ntitle = "c"\n[design]\ntype = "within"\n[input]\ntype = "walker"\n[clips]\nseconds = 0.5\n[[stimuli]]\nid = "GL"\nsurface = "gravel"\n[[stimuli]]\nid = "WD"\nsurface = "wood"\n[[questions.scales]]\nid = "realism"\nprompt = "R"\nmin = 1\nmax = 7\n' > cl.toml
"$underfoot" clips --protocol cl.toml -o clips --live --settings audio.toml > clips.txt 2>&1 ||
  { cat clips.txt; exit 1; }
grep -q "live audio: jack" clips.txt
grep -q "playing 2 of 2" clips.txt
echo "live session end to end: ok"
