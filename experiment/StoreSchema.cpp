// SPDX-License-Identifier: GPL-3.0-or-later
// The study file's schema: every migration from an empty file to kSchemaVersion.
#include "experiment/Store.h"
#include "experiment/StoreInternal.h"

namespace underfoot::experiment::store_detail {

namespace {

/// Schema migrations: entry i brings user_version from i to i + 1. Never edit a shipped entry;
/// append a new one (and bump kSchemaVersion).
const char* const kMigrations[] = {
    // 0 -> 1: initial schema.
    R"sql(
CREATE TABLE study (
  id INTEGER PRIMARY KEY CHECK (id = 1),
  code TEXT NOT NULL,
  site TEXT NOT NULL,
  seed INTEGER NOT NULL,
  created_at TEXT NOT NULL,
  app_version TEXT NOT NULL
);
CREATE TABLE protocol (
  id INTEGER PRIMARY KEY CHECK (id = 1),
  protocol_id TEXT NOT NULL,
  version INTEGER NOT NULL,
  source_name TEXT NOT NULL,
  text TEXT NOT NULL,
  hash TEXT NOT NULL,
  stored_at TEXT NOT NULL
);
CREATE TABLE participants (
  id INTEGER PRIMARY KEY,
  code TEXT NOT NULL UNIQUE,
  idx INTEGER NOT NULL UNIQUE,
  age INTEGER,
  gender TEXT NOT NULL DEFAULT '',
  shoes TEXT NOT NULL DEFAULT '',
  hearing TEXT NOT NULL DEFAULT '',
  group_id TEXT NOT NULL,
  assignment TEXT NOT NULL CHECK (assignment IN ('balanced', 'override')),
  override_reason TEXT NOT NULL DEFAULT '',
  status TEXT NOT NULL CHECK (status IN ('registered', 'active', 'completed', 'dropped')),
  seed INTEGER NOT NULL,
  registered_at TEXT NOT NULL
);
CREATE TABLE sessions (
  id INTEGER PRIMARY KEY,
  participant_id INTEGER NOT NULL REFERENCES participants(id),
  number INTEGER NOT NULL,
  group_id TEXT NOT NULL,
  seed INTEGER NOT NULL,
  app_version TEXT NOT NULL,
  audio_config TEXT NOT NULL,
  sensor_config TEXT NOT NULL,
  experimenter TEXT NOT NULL,
  started_at TEXT NOT NULL,
  ended_at TEXT,
  outcome TEXT,
  UNIQUE (participant_id, number)
);
CREATE TABLE trials (
  id INTEGER PRIMARY KEY,
  participant_id INTEGER NOT NULL REFERENCES participants(id),
  trial_index INTEGER NOT NULL,
  block INTEGER NOT NULL,
  practice INTEGER NOT NULL CHECK (practice IN (0, 1)),
  stimulus_id TEXT NOT NULL,
  stimulus TEXT NOT NULL,
  repetition INTEGER NOT NULL,
  break_after INTEGER NOT NULL CHECK (break_after IN (0, 1)),
  planned_seed INTEGER NOT NULL,
  session_number INTEGER,
  render_seed INTEGER,
  grf_recording TEXT,
  started_at TEXT,
  answered_at TEXT,
  response_time_s REAL,
  answer TEXT,
  soundscape_answer TEXT,
  comment TEXT,
  excluded INTEGER NOT NULL DEFAULT 0 CHECK (excluded IN (0, 1)),
  exclusion_reason TEXT NOT NULL DEFAULT '',
  UNIQUE (participant_id, trial_index)
);
CREATE TABLE ratings (
  trial_id INTEGER NOT NULL REFERENCES trials(id),
  scale TEXT NOT NULL,
  value INTEGER NOT NULL,
  PRIMARY KEY (trial_id, scale)
);
CREATE TABLE events (
  id INTEGER PRIMARY KEY AUTOINCREMENT,
  at TEXT NOT NULL,
  kind TEXT NOT NULL,
  participant_id INTEGER,
  trial_index INTEGER,
  detail TEXT NOT NULL
);
CREATE TRIGGER events_no_update BEFORE UPDATE ON events
  BEGIN SELECT RAISE(ABORT, 'the event journal is append-only'); END;
CREATE TRIGGER events_no_delete BEFORE DELETE ON events
  BEGIN SELECT RAISE(ABORT, 'the event journal is append-only'); END;
)sql",
    // 1 -> 2: listening tests and interactive laps; participant fields.
    R"sql(
ALTER TABLE trials ADD COLUMN replays INTEGER NOT NULL DEFAULT 0;
ALTER TABLE trials ADD COLUMN laps_done INTEGER NOT NULL DEFAULT 0;
CREATE TABLE participant_fields (
  participant_id INTEGER NOT NULL REFERENCES participants(id),
  name TEXT NOT NULL,
  value TEXT NOT NULL,
  PRIMARY KEY (participant_id, name)
);
)sql",
    // 2 -> 3: live trials: audio figures, sensor log, sensor-fault interruptions.
    R"sql(
ALTER TABLE trials ADD COLUMN audio_sample_rate_hz REAL;
ALTER TABLE trials ADD COLUMN audio_block_size INTEGER;
ALTER TABLE trials ADD COLUMN audio_frames INTEGER;
ALTER TABLE trials ADD COLUMN audio_xruns INTEGER;
ALTER TABLE trials ADD COLUMN audio_average_load_percent REAL;
ALTER TABLE trials ADD COLUMN audio_max_load_percent REAL;
ALTER TABLE trials ADD COLUMN audio_max_block_ms REAL;
ALTER TABLE trials ADD COLUMN audio_dropped_grf_frames INTEGER;
ALTER TABLE trials ADD COLUMN sensor_log TEXT;
ALTER TABLE trials ADD COLUMN interruptions INTEGER NOT NULL DEFAULT 0;
ALTER TABLE trials ADD COLUMN interruption_reason TEXT NOT NULL DEFAULT '';
)sql",
    // 3 -> 4: simulated participants are flagged as such (a
    // simulation never writes into a real participant); each session stores whether sound was
    // played (1), not (0: data entry without sound), or is unknown (NULL, older sessions).
    R"sql(
ALTER TABLE participants ADD COLUMN simulated INTEGER NOT NULL DEFAULT 0
  CHECK (simulated IN (0, 1));
ALTER TABLE sessions ADD COLUMN sound_played INTEGER CHECK (sound_played IN (0, 1));
)sql",
    // 4 -> 5: online invitations (token stored only
    // as its SHA-256), online sessions (user agent, audio output rate) and answer attempts
    // (idempotent submissions, browser response times). Used by experiment/Invitations.cpp.
    R"sql(
CREATE TABLE IF NOT EXISTS online_invitations (
  id INTEGER PRIMARY KEY,
  token_sha256 TEXT NOT NULL UNIQUE,
  participant_code TEXT NOT NULL UNIQUE,
  group_override TEXT,
  completion_code TEXT NOT NULL,
  created_at TEXT NOT NULL,
  consented_at TEXT,
  screening_passed INTEGER,
  screening_detail TEXT NOT NULL DEFAULT '',
  screened_at TEXT
);
CREATE TABLE IF NOT EXISTS online_sessions (
  invitation_id INTEGER NOT NULL REFERENCES online_invitations(id),
  session_number INTEGER NOT NULL,
  started_at TEXT NOT NULL,
  user_agent TEXT NOT NULL DEFAULT '',
  audio_sample_rate_hz REAL,
  PRIMARY KEY (invitation_id, session_number)
);
CREATE TABLE IF NOT EXISTS online_answers (
  invitation_id INTEGER NOT NULL REFERENCES online_invitations(id),
  trial_index INTEGER NOT NULL,
  attempt_id TEXT NOT NULL,
  client_response_time_ms REAL,
  received_at TEXT NOT NULL,
  PRIMARY KEY (invitation_id, trial_index)
);
)sql",
    // 5 -> 6: session leases, one live session per participant.
    R"sql(
CREATE TABLE session_leases (
  participant_id INTEGER PRIMARY KEY REFERENCES participants(id),
  token TEXT NOT NULL,
  pid INTEGER NOT NULL,
  host TEXT NOT NULL,
  experimenter TEXT NOT NULL,
  session_number INTEGER NOT NULL,
  since TEXT NOT NULL
);
)sql",
    // 6 -> 7: the clip a listening-test trial played (file, length, rate, samples' SHA-256),
    // so that a replay proves it returns what was heard.
    R"sql(
ALTER TABLE trials ADD COLUMN clip_file TEXT;
ALTER TABLE trials ADD COLUMN clip_seconds REAL;
ALTER TABLE trials ADD COLUMN clip_frames INTEGER;
ALTER TABLE trials ADD COLUMN clip_sample_rate_hz REAL;
ALTER TABLE trials ADD COLUMN clip_sha256 TEXT;
)sql",
    // 7 -> 8: a lease names its holder by PID, process start time and boot id, so that a
    // reused PID or a reboot is not mistaken for a live holder.
    R"sql(
ALTER TABLE session_leases ADD COLUMN start_ticks INTEGER;
ALTER TABLE session_leases ADD COLUMN boot_id TEXT NOT NULL DEFAULT '';
)sql",
};
constexpr int kMigrationCount = static_cast<int>(sizeof(kMigrations) / sizeof(kMigrations[0]));
static_assert(kMigrationCount == kSchemaVersion);

} // namespace

const char* migration(int fromVersion) {
    return kMigrations[fromVersion];
}
int migrationCount() {
    return kMigrationCount;
}

} // namespace underfoot::experiment::store_detail
