#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The online listening test end to end in a real browser, for three protocols (wading realism,
# wading listening, a TVCG-style identification with pre-rendered clips):
#   study create -> clips -> study invite -> serve -> headless Chromium from consent to the
#   completion code by keyboard (drive.mjs) -> SIGTERM -> the study file holds the answers,
#   the browser's response times, user agent and audio rate -> simulated booth participants in
#   the same study -> export and analyze show both.
# Usage: run.sh UNDERFOOT SOURCE_DIR WORK_DIR CHROMIUM
# Screenshots go to $UNDERFOOT_WEB_SCREENSHOTS (default WORK_DIR/screenshots; the ones in
# docs/web/ were made with UNDERFOOT_WEB_SCREENSHOTS=docs/web).
set -euo pipefail
uf=$(realpath "$1"); src=$(realpath "$2"); work=$3; chromium=$4
shots=$(realpath -m "${UNDERFOOT_WEB_SCREENSHOTS:-$work/screenshots}")
here=$src/tests/web/browser
if [ ! -d "$here/node_modules/puppeteer-core" ]; then
  echo "run.sh: puppeteer-core is missing; run (cd tests/web/browser && PUPPETEER_SKIP_DOWNLOAD=1 npm ci)" \
       "as scripts/setup.sh does" >&2
  exit 1
fi
rm -rf "$work"; mkdir -p "$work" "$shots"
work=$(realpath "$work")

fail() { echo "run.sh: $*" >&2; exit 1; }
q() { sqlite3 "$1" "$2"; }

run_one() {
  local name=$1 protocol=$2 d=$work/$1
  local booth=${3:-booth}
  mkdir -p "$d/clips"
  "$uf" study create --study "$d/online.db" --protocol "$protocol" --code WEB --site web --seed 4
  if grep -q 'clip = "real/' "$protocol"; then
    # Stand-ins for the lab's real recordings (the study's are from a commercial library).
    python3 - "$d/clips/real" <<'PY'
import math, os, struct, sys, wave, random
os.makedirs(sys.argv[1], exist_ok=True)
for spm in (27, 63, 118):
    rng = random.Random(spm)
    with wave.open(os.path.join(sys.argv[1], f"wading_{spm}spm.wav"), "wb") as w:
        w.setnchannels(1); w.setsampwidth(2); w.setframerate(48000)
        frames = bytearray()
        for i in range(48000 * 2):
            env = 0.5 * (1 - math.cos(2 * math.pi * (i / 48000) * spm / 60))
            frames += struct.pack("<h", int(3000 * env * (rng.random() * 2 - 1)))
        w.writeframes(bytes(frames))
PY
  fi
  "$uf" clips --protocol "$protocol" -o "$d/clips" > "$d/clips.log"
  local port
  port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  "$uf" study invite --study "$d/online.db" --count 2 --base-url "http://127.0.0.1:$port" -o "$d/links.csv"
  "$uf" serve --study "$d/online.db" --clips "$d/clips" --port "$port" > "$d/serve.log" 2>&1 &
  local pid=$!
  for _ in $(seq 100); do grep -q "listening on" "$d/serve.log" && break; sleep 0.1; done
  grep -q "listening on http://127.0.0.1:$port/" "$d/serve.log" || { cat "$d/serve.log"; fail "$name: serve did not start"; }
  local link; link=$(sed -n 2p "$d/links.csv" | cut -d, -f2)
  if ! (cd "$here" && timeout 300 node drive.mjs "$link" "$shots" "$name" "$chromium" "$d/result.json"); then
    kill -TERM "$pid" || true; wait "$pid" || true
    cat "$d/serve.log"; fail "$name: the browser run failed"
  fi
  kill -TERM "$pid"; wait "$pid" || fail "$name: serve did not exit cleanly"
  grep -q "stopped (SIGTERM)" "$d/serve.log" || { cat "$d/serve.log"; fail "$name: no clean stop"; }

  # The study file: every trial answered once, browser times beside server times, the client.
  local db=$d/online.db pid_sql="(SELECT id FROM participants WHERE code = 'W001')"
  [ "$(q "$db" "SELECT status FROM participants WHERE code = 'W001'")" = completed ] || fail "$name: W001 not completed"
  local planned answered
  planned=$(q "$db" "SELECT count(*) FROM trials WHERE participant_id = $pid_sql")
  answered=$(q "$db" "SELECT count(*) FROM trials WHERE participant_id = $pid_sql AND answered_at IS NOT NULL AND response_time_s IS NOT NULL")
  [ "$planned" -gt 0 ] && [ "$planned" = "$answered" ] || fail "$name: $answered of $planned trials answered"
  [ "$(q "$db" "SELECT count(*) FROM events WHERE kind = 'answered' AND participant_id = $pid_sql")" = "$planned" ] \
    || fail "$name: answers journaled more than once"
  [ "$(q "$db" "SELECT count(*) FROM online_answers a JOIN online_invitations i ON i.id = a.invitation_id WHERE i.participant_code = 'W001' AND a.client_response_time_ms > 0")" = "$planned" ] \
    || fail "$name: browser response times missing"
  q "$db" "SELECT user_agent, audio_sample_rate_hz FROM online_sessions" | grep -q 'Chrome.*|[0-9]' \
    || fail "$name: user agent / audio sample rate not stored"
  [ "$(q "$db" "SELECT screening_passed FROM online_invitations WHERE participant_code = 'W001'")" = 1 ] \
    || fail "$name: headphone screening not passed/stored"
  # Scored by the server from the choices the page forwarded: the driver heard every triplet.
  [ "$(q "$db" "SELECT json_extract(screening_detail, '\$.correct') FROM online_invitations WHERE participant_code = 'W001'")" = 6 ] \
    || fail "$name: the server did not score 6 of 6 headphone-check choices"
  local want_replays=1; grep -q '^replay = false' "$protocol" && want_replays=0
  [ "$(q "$db" "SELECT sum(replays) FROM trials WHERE participant_id = $pid_sql")" = "$want_replays" ] \
    || fail "$name: expected $want_replays counted replay(s)"
  local code; code=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["completionCode"])' "$d/result.json")
  [ "$(q "$db" "SELECT completion_code FROM online_invitations WHERE participant_code = 'W001'")" = "$code" ] \
    || fail "$name: the completion code shown is not the stored one"

  # Booth participants (simulated) in the same study; export and analyze show both.
  # (`session --simulate` answers only the scales of a [clips] protocol, not an identification
  # list: the identification protocol's export and analysis hold the online participant only.)
  if [ "$booth" = booth ]; then
    "$uf" session --study "$d/online.db" --simulate --participants 3 --prefix B > "$d/simulate.log"
  fi
  "$uf" export --study "$d/online.db" -o "$d/export" > /dev/null
  grep -q ',W001,' "$d/export/trials.csv" || fail "$name: W001 missing from the export"
  if [ "$booth" = booth ]; then
    grep -q ',B00[0-9],' "$d/export/trials.csv" || fail "$name: booth participants missing from the export"
  fi
  "$uf" analyze --study "$d/online.db" --format markdown -o "$d/report.md" > /dev/null
  echo "run.sh: $name ok: $(cat "$d/result.json" | tr -d '\n ')"
}

run_one wading_realism "$src/protocols/wading_realism.toml"
run_one wading_listening "$src/protocols/wading_listening.toml"
run_one tvcg_identification "$here/tvcg_identification_clips.toml" online-only
echo "run.sh: all three protocols ran end to end in Chromium"
