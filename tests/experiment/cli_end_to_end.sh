#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# End to end through the `underfoot` program: create the TVCG 2011 exp. 2 study, simulate its
# 43 participants from the published per-group confusion matrices, export, and check the files.
#   cli_end_to_end.sh UNDERFOOT SOURCE_DIR WORK_DIR
set -euo pipefail
underfoot="$1"; src="$2"; work="$3"
data="$src/tests/experiment/data"
rm -rf "$work"; mkdir -p "$work"; cd "$work"

"$underfoot" protocol check "$src/protocols/tvcg2011_exp2.toml" > check.txt
grep -q "incoherent .* 12 " check.txt

"$underfoot" study create --study exp2.db --protocol "$src/protocols/tvcg2011_exp2.toml" \
  --code TVCG2 --site ci --seed 2011 > /dev/null
"$underfoot" session --study exp2.db --simulate --participants 43 \
  --confusion "none=$data/tvcg2011_exp2_cond1_no_soundscape_confusion.csv" \
  --confusion "coherent=$data/tvcg2011_exp2_cond2_coherent_confusion.csv" \
  --confusion "incoherent=$data/tvcg2011_exp2_cond3_incoherent_confusion.csv" > simulate.txt
"$underfoot" export --study exp2.db -o out > /dev/null

# 15 x 10 + 15 x 10 + 13 x 12 = 456 trials, plus the header.
test "$(wc -l < out/trials.csv)" -eq 457
head -1 out/trials.csv | tr -d '\r' | grep -qx "study,site,protocol_id,protocol_hash,participant,group,session,trial_index,block,practice,stimulus_id,surface,soundscape,modalities,reverb,repetition,render_seed,answer,answer_label,correct,realism,quality,soundscape_answer,soundscape_correct,response_time_s,excluded,exclusion_reason,comment,started_at,answered_at,trial,simulated,clip_file,clip_frames,clip_rate,clip_sha256"
for g in none coherent incoherent; do
  n=$(cut -d, -f5,6 out/trials.csv | grep ",$g\$" | sort -u | wc -l)
  case $g in none|coherent) test "$n" -eq 15 ;; incoherent) test "$n" -eq 13 ;; esac
done
grep -q '`soundscape_correct`' out/codebook.md

# A changed protocol is refused for the existing study.
sed 's/repetitions = 2/repetitions = 3/' "$src/protocols/tvcg2011_exp2.toml" > changed.toml
if "$underfoot" session --study exp2.db --simulate --participants 44 --protocol changed.toml \
     --confusion "$data/tvcg2011_exp2_cond1_no_soundscape_confusion.csv" 2> refused.txt; then
  echo "a changed protocol was accepted"; exit 1
fi
grep -q "differs from the protocol" refused.txt

# A protocol with problems: every one reported with file:line:column, exit status 2.
printf '[protocol]\nid = "x"\nversion = 1\ntitle = "x"\n[design]\ntype = "within"\n[[stimuli]]\nid = "A"\nsurface = "sand"\n[[stimuli]]\nid = "B"\nsurface = "wood"\nsoundscape = "moon"\n[questions.surface]\noptions = ["wood"]\n' > bad.toml
set +e
"$underfoot" protocol check bad.toml 2> bad.txt
status=$?
set -e
test "$status" -eq 2
grep -q "bad.toml:9:11: unknown surface 'sand'" bad.txt
grep -q "bad.toml:13:14: unknown soundscape 'moon'" bad.txt
echo "end to end: ok"
