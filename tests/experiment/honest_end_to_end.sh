#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Through the `underfoot` program: every shipped protocol simulates with no further
# argument (the published data it names) and never touches a real participant; simulated
# participants are flagged in the export and left out of `analyze`; a session without --live
# says that no sound is played and stores it; trial numbers people type are 1-based;
# `study participants -o dir/file.csv` creates dir/; an unknown surface gets a suggestion.
#   honest_end_to_end.sh UNDERFOOT SOURCE_DIR WORK_DIR
set -euo pipefail
underfoot="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"

col() { head -1 "$1" | tr -d '\r' | tr ',' '\n' | grep -nx "$2" | cut -d: -f1; }

for protocol in "$src"/protocols/*.toml; do
  name=$(basename "$protocol" .toml)
  "$underfoot" study create --study "$name.db" --protocol "$protocol" --code H --site ci \
    --seed 17 > /dev/null
  fields=()
  if [ "$name" = wading_realism ]; then
    fields=(--field music_expertise=none --field audio_expertise=casual_amateur
            --field listening_device=laptop_speakers)
  fi
  "$underfoot" study register --study "$name.db" --participant P01 "${fields[@]}" > /dev/null
  "$underfoot" session --study "$name.db" --simulate --participants 2 > "$name.sim.txt" \
    2>&1 || { echo "$name: simulation failed"; cat "$name.sim.txt"; exit 1; }
  grep -q "1 real participant left untouched" "$name.sim.txt"
  grep -q "2 simulated and 1 real participants" "$name.sim.txt"
  grep -q "named by the protocol" "$name.sim.txt"
  "$underfoot" export --study "$name.db" -o "$name.out" > /dev/null
  sim=$(col "$name.out/trials.csv" simulated)
  who=$(col "$name.out/trials.csv" participant)
  # Every exported (answered) row is a simulated participant's; P01 has none.
  test "$(tail -n +2 "$name.out/trials.csv" | cut -d, -f"$sim" | tr -d '\r' | sort -u)" = "1"
  ! tail -n +2 "$name.out/trials.csv" | cut -d, -f"$who" | grep -qx P01
  "$underfoot" study info --study "$name.db" > "$name.info.txt"
  grep -E "^P01 .* registered +0/" "$name.info.txt" > /dev/null
  test "$(grep -c SIMULATED "$name.info.txt")" -eq 2
done
grep -q '`simulated`' tvcg2011_exp1.out/codebook.md

# The trial people read: `trial` = trial_index + 1.
t=$(col tvcg2011_exp1.out/trials.csv trial); i=$(col tvcg2011_exp1.out/trials.csv trial_index)
tail -n +2 tvcg2011_exp1.out/trials.csv | awk -F, -v t="$t" -v i="$i" '$t != $i + 1 { exit 1 }'

# analyze: simulated participants out unless asked for.
set +e
"$underfoot" analyze --study tvcg2011_exp1.db > real.md 2> real.err
set -e
grep -q "2 simulated participants left out" real.err
"$underfoot" analyze --study tvcg2011_exp1.db --include-simulated > all.md
grep -q "| Stimulus |" all.md

# A person's session: NO SOUND said at the start and stored; a simulated code is refused.
printf 'quit\n' | "$underfoot" session --study tvcg2011_exp1.db --participant P01 > p01.txt || true
grep -q "NO SOUND" p01.txt
"$underfoot" study events --study tvcg2011_exp1.db | grep session_started | grep -q '"sound":"none (data entry)"'
set +e
printf 'quit\n' | "$underfoot" session --study tvcg2011_exp1.db --participant S002 > s.txt 2> s.err
status=$?
set -e
test "$status" -ne 0
grep -q "is a simulated participant" s.err

# 1-based numbers people type: `study trial --trial 1` is the first trial (stored index 0).
"$underfoot" study trial --study tvcg2011_exp1.db --participant S002 --trial 1 > t1.txt
grep -q "trial 1 (stored index 0)" t1.txt
set +e
"$underfoot" study trial --study tvcg2011_exp1.db --participant S002 --trial 0 > /dev/null 2>&1
status=$?
set -e
test "$status" -ne 0

# `study participants -o dir/file.csv` creates dir/.
"$underfoot" study participants --study tvcg2011_exp1.db -o new/sub/p.csv > /dev/null
test -s new/sub/p.csv

# An unknown surface: sorted list and the closest name.
printf '[protocol]\nid = "x"\nversion = 1\ntitle = "x"\n[design]\ntype = "within"\n[[stimuli]]\nid = "A"\nsurface = "gravle"\n[questions.surface]\noptions = ["gravel"]\n' > bad.toml
set +e
"$underfoot" protocol check bad.toml 2> bad.txt
set -e
grep -q "did you mean 'gravel'" bad.txt
grep -q "beach_sand, carpet, concrete" bad.txt
set +e
"$underfoot" render --surface gravle --seconds 1 -o x.wav 2> render.txt
set -e
grep -q "did you mean 'gravel'" render.txt

# clips --live refuses with the reason when no sound can be played (here: no settings file).
printf '[protocol]\nid = "cl"\nversion = 1\ntitle = "c"\n[design]\ntype = "within"\n[input]\ntype = "walker"\n[clips]\nseconds = 0.5\n[[stimuli]]\nid = "GL"\nsurface = "gravel"\n[[questions.scales]]\nid = "realism"\nprompt = "R"\nmin = 1\nmax = 7\n' > cl.toml
"$underfoot" clips --protocol cl.toml -o clips > /dev/null
set +e
"$underfoot" clips --protocol cl.toml -o clips --check --live --settings missing.toml \
  > clips.txt 2>&1
status=$?
set -e
test "$status" -ne 0
grep -q "no sound can be played" clips.txt
echo "honest end to end: ok"
