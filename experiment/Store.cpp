// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Store.h"

#include "experiment/Random.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <random>

#include <signal.h>
#include <sqlite3.h>
#include <unistd.h>

namespace underfoot::experiment {

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
    // 3 -> 4 (issue #17, task "honest"): simulated participants are flagged as such (a
    // simulation never writes into a real participant); each session stores whether sound was
    // played (1), not (0: data entry without sound), or is unknown (NULL, older sessions).
    R"sql(
ALTER TABLE participants ADD COLUMN simulated INTEGER NOT NULL DEFAULT 0
  CHECK (simulated IN (0, 1));
ALTER TABLE sessions ADD COLUMN sound_played INTEGER CHECK (sound_played IN (0, 1));
)sql",
    // 4 -> 5 (issue 14, `underfoot serve`, task "web"): online invitations (token stored only
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
    // 5 -> 6 (issue #16, hardening): session leases, one live session per participant.
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
};
constexpr int kMigrationCount = static_cast<int>(sizeof(kMigrations) / sizeof(kMigrations[0]));
static_assert(kMigrationCount == kSchemaVersion);

std::int64_t toDb(std::uint64_t v) {
    return static_cast<std::int64_t>(v);
}
std::uint64_t fromDb(std::int64_t v) {
    return static_cast<std::uint64_t>(v);
}

std::string columnText(const SQLite::Column& c) {
    return c.isNull() ? std::string() : c.getString();
}

ParticipantStatus statusFromText(const std::string& s) {
    if (s == "active") return ParticipantStatus::Active;
    if (s == "completed") return ParticipantStatus::Completed;
    if (s == "dropped") return ParticipantStatus::Dropped;
    return ParticipantStatus::Registered;
}

constexpr const char* kParticipantColumns =
    "id, code, idx, age, gender, shoes, hearing, group_id, assignment, override_reason, status, "
    "registered_at, simulated";

ParticipantInfo readParticipant(SQLite::Statement& q) {
    ParticipantInfo p;
    p.id = q.getColumn(0).getInt64();
    p.code = q.getColumn(1).getString();
    p.index = q.getColumn(2).getInt();
    if (!q.getColumn(3).isNull()) p.age = q.getColumn(3).getInt();
    p.gender = q.getColumn(4).getString();
    p.shoes = q.getColumn(5).getString();
    p.hearing = q.getColumn(6).getString();
    p.groupId = q.getColumn(7).getString();
    p.assignment =
        q.getColumn(8).getString() == "override" ? Assignment::Override : Assignment::Balanced;
    p.overrideReason = q.getColumn(9).getString();
    p.status = statusFromText(q.getColumn(10).getString());
    p.registeredAt = q.getColumn(11).getString();
    p.simulated = q.getColumn(12).getInt() != 0;
    return p;
}

} // namespace

const char* toString(ParticipantStatus status) {
    switch (status) {
    case ParticipantStatus::Registered:
        return "registered";
    case ParticipantStatus::Active:
        return "active";
    case ParticipantStatus::Completed:
        return "completed";
    case ParticipantStatus::Dropped:
        return "dropped";
    }
    return "registered";
}

std::string isoUtc(std::chrono::system_clock::time_point t) {
    const auto ms =
        std::chrono::duration_cast<std::chrono::milliseconds>(t.time_since_epoch()).count();
    const std::time_t seconds = static_cast<std::time_t>(ms / 1000 - (ms % 1000 < 0 ? 1 : 0));
    const long millis = static_cast<long>(((ms % 1000) + 1000) % 1000);
    std::tm tm{};
    gmtime_r(&seconds, &tm);
    return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}.{:03}Z", tm.tm_year + 1900,
                       tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, millis);
}

std::string jsonObject(std::initializer_list<std::pair<std::string_view, std::string>> fields) {
    std::string out = "{";
    auto escape = [](std::string_view s) {
        std::string e;
        for (const char c : s) {
            switch (c) {
            case '"':
                e += "\\\"";
                break;
            case '\\':
                e += "\\\\";
                break;
            case '\n':
                e += "\\n";
                break;
            case '\r':
                e += "\\r";
                break;
            case '\t':
                e += "\\t";
                break;
            default:
                if (static_cast<unsigned char>(c) < 0x20)
                    e += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
                else
                    e += c;
            }
        }
        return e;
    };
    bool first = true;
    for (const auto& [key, value] : fields) {
        if (!first) out += ',';
        first = false;
        out += '"' + escape(key) + "\":\"" + escape(value) + '"';
    }
    return out + "}";
}

// ----------------------------------------------------------------------------------------------

namespace {

std::string hostName() {
    char buf[256] = {};
    if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown-host";
    return buf;
}

std::string newLeaseToken() {
    std::random_device rd;
    return fmt::format("{:08x}{:08x}{:08x}", rd(), rd(), static_cast<unsigned>(::getpid()));
}

/// True when `pid` on this host is certainly gone (a crashed session).
bool processIsGone(std::int64_t pid) {
    if (pid <= 0) return true;
    return ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
}

/// The first problems PRAGMA quick_check reports ("ok" -> empty), within a time bound.
std::string quickCheck(SQLite::Database& db, std::chrono::milliseconds bound) {
    struct Deadline {
        std::chrono::steady_clock::time_point at;
        bool expired = false;
    } deadline{std::chrono::steady_clock::now() + bound};
    sqlite3_progress_handler(
        db.getHandle(), 10000,
        [](void* p) -> int {
            auto* d = static_cast<Deadline*>(p);
            d->expired = std::chrono::steady_clock::now() > d->at;
            return d->expired ? 1 : 0;
        },
        &deadline);
    std::string problems;
    try {
        SQLite::Statement q(db, "PRAGMA quick_check(5)");
        while (q.executeStep()) {
            const std::string line = q.getColumn(0).getString();
            if (line == "ok") break;
            problems += (problems.empty() ? "" : "; ") + line;
        }
    } catch (const SQLite::Exception& e) {
        if (!deadline.expired) problems = e.what(); // interrupted by the bound: not checked
    }
    sqlite3_progress_handler(db.getHandle(), 0, nullptr, nullptr);
    return problems;
}

std::string recoveryHint(const std::string& path) {
    return fmt::format(
        "nothing was written to it. To recover: keep the file as it is, make a copy, and "
        "rebuild it with `sqlite3 {0} \".recover\" | sqlite3 recovered.db`, or go back to "
        "a backup (`sqlite3 {0} \".backup copy.db\"` makes one); the events table is the "
        "journal of every acknowledged answer to check the result against",
        path);
}

} // namespace

StudyStore::StudyStore(std::string path, std::unique_ptr<SQLite::Database> db, Clock clock)
    : path_(std::move(path)), db_(std::move(db)), clock_(std::move(clock)),
      leaseToken_(newLeaseToken()) {}
StudyStore::StudyStore(StudyStore&&) noexcept = default;
StudyStore& StudyStore::operator=(StudyStore&&) noexcept = default;
StudyStore::~StudyStore() = default;

std::string StudyStore::now() const {
    return isoUtc(clock_.now());
}

void StudyStore::configure() {
    db_->exec("PRAGMA journal_mode=WAL");
    db_->exec("PRAGMA synchronous=FULL");
    db_->exec("PRAGMA foreign_keys=ON");
    db_->setBusyTimeout(5000);
    // Migrations, each in its own transaction together with the version bump.
    const int version = db_->execAndGet("PRAGMA user_version").getInt();
    if (version > kSchemaVersion)
        throw StoreError(fmt::format("{}: schema version {} was written by a newer Underfoot; "
                                     "this version reads up to {}",
                                     path_, version, kSchemaVersion));
    // A damaged or foreign file can carry any 32-bit user_version; only 0..kSchemaVersion are
    // ours (a negative one used to index the migrations at -1, issue #16).
    if (version < 0)
        throw StoreError(fmt::format("{}: schema version {} is not one Underfoot ever wrote "
                                     "(expected 1 to {}); the file is damaged or not a study",
                                     path_, version, kSchemaVersion));
    for (int v = version; v < kSchemaVersion; ++v) {
        SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
        db_->exec(kMigrations[v]);
        db_->exec(fmt::format("PRAGMA user_version = {}", v + 1));
        if (version > 0) // a real migration of an existing study is journaled
            appendEvent("schema_migrated", std::nullopt, std::nullopt,
                        jsonObject({{"from", std::to_string(v)}, {"to", std::to_string(v + 1)}}));
        tx.commit();
    }
}

StudyStore StudyStore::create(const std::string& path, const Protocol& protocol,
                              const StudySettings& settings, Clock clock,
                              const Catalogue& catalogue) {
    if (std::filesystem::exists(path))
        throw StoreError(fmt::format("{}: the file already exists; expected a new study file "
                                     "(open the existing study instead)",
                                     path));
    if (settings.code.empty()) throw StoreError(fmt::format("{}: the study needs a code", path));
    auto db =
        std::make_unique<SQLite::Database>(path, SQLite::OPEN_READWRITE | SQLite::OPEN_CREATE);
    StudyStore store(path, std::move(db), std::move(clock));
    store.configure();
    SQLite::Transaction tx(*store.db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::string at = store.now();
    SQLite::Statement study(*store.db_, "INSERT INTO study (id, code, site, seed, created_at, "
                                        "app_version) VALUES (1, ?, ?, ?, ?, ?)");
    study.bind(1, settings.code);
    study.bind(2, settings.site);
    study.bind(3, toDb(settings.seed));
    study.bind(4, at);
    study.bind(5, settings.appVersion);
    study.exec();
    SQLite::Statement proto(*store.db_, "INSERT INTO protocol (id, protocol_id, version, "
                                        "source_name, text, hash, stored_at) VALUES "
                                        "(1, ?, ?, ?, ?, ?, ?)");
    proto.bind(1, protocol.id);
    proto.bind(2, protocol.version);
    proto.bind(3, protocol.sourceName);
    proto.bind(4, protocol.sourceText);
    proto.bind(5, protocol.hash);
    proto.bind(6, at);
    proto.exec();
    store.appendEvent("study_created", std::nullopt, std::nullopt,
                      jsonObject({{"code", settings.code},
                                  {"site", settings.site},
                                  {"seed", std::to_string(settings.seed)},
                                  {"protocol", protocol.id},
                                  {"hash", protocol.hash}}));
    tx.commit();
    store.loadProtocol(catalogue);
    return store;
}

StudyStore StudyStore::open(const std::string& path, Clock clock, const Catalogue& catalogue) {
    if (!std::filesystem::exists(path))
        throw StoreError(fmt::format("{}: no such study file; expected a file made by "
                                     "`underfoot study create`",
                                     path));
    // Say plainly when this user may not write the study (SQLite would open it read-only, or
    // fail to create its -wal/-shm files, with a misleading message; issue #16).
    const std::string folder = std::filesystem::absolute(path).parent_path().string();
    if (::access(path.c_str(), R_OK) != 0)
        throw StoreError(
            fmt::format("{}: cannot read the study file ({})", path, std::strerror(errno)));
    if (::access(path.c_str(), W_OK) != 0)
        throw StoreError(fmt::format("{}: the study file is read-only for this user ({}); "
                                     "expected a writable file: make it writable (and its "
                                     "folder {}), or work on a copy",
                                     path, std::strerror(errno), folder));
    if (::access(folder.c_str(), W_OK | X_OK) != 0)
        throw StoreError(fmt::format("{}: the folder {} is read-only for this user ({}); SQLite "
                                     "must create {}-wal and {}-shm next to the study: make the "
                                     "folder writable, or work on a copy elsewhere",
                                     path, folder, std::strerror(errno), path, path));
    std::unique_ptr<SQLite::Database> db;
    try {
        db = std::make_unique<SQLite::Database>(path, SQLite::OPEN_READWRITE);
        db->execAndGet("SELECT count(*) FROM sqlite_master");
    } catch (const SQLite::Exception& e) {
        throw StoreError(fmt::format("{}: not a readable study file ({})", path, e.what()));
    }
    // A damaged file is refused before anything is written to it (issue #16).
    if (const std::string problems = quickCheck(*db, std::chrono::seconds(10)); !problems.empty())
        throw StoreError(fmt::format("{}: the study file is damaged (SQLite integrity check: {}); "
                                     "{}",
                                     path, problems, recoveryHint(path)));
    StudyStore store(path, std::move(db), std::move(clock));
    const int version = store.db_->execAndGet("PRAGMA user_version").getInt();
    if (version <= 0)
        throw StoreError(fmt::format("{}: not an Underfoot study (schema version {}; expected "
                                     "1 to {})",
                                     path, version, kSchemaVersion));
    try {
        store.configure();
        store.loadProtocol(catalogue);
    } catch (const SQLite::Exception& e) {
        store.writeFailed("opening the study", e);
    }
    return store;
}

namespace {

/// `path` as an SQLite URI filename ("file:" + percent-encoded path) with `query`.
std::string sqliteUri(const std::string& path, const std::string& query) {
    std::string uri = "file:";
    for (const char c : std::filesystem::absolute(path).string()) {
        const auto u = static_cast<unsigned char>(c);
        if (std::isalnum(u) || c == '/' || c == '-' || c == '_' || c == '.' || c == '~')
            uri += c;
        else
            uri += fmt::format("%{:02X}", u);
    }
    return uri + "?" + query;
}

bool writableByThisUser(const std::string& path, int mode) {
    return ::access(path.c_str(), mode) == 0;
}

} // namespace

StudyStore StudyStore::openReadOnly(const std::string& path, Clock clock,
                                    const Catalogue& catalogue) {
    if (!std::filesystem::exists(path))
        throw StoreError(fmt::format("{}: no such study file; expected a file made by "
                                     "`underfoot study create`",
                                     path));
    if (::access(path.c_str(), R_OK) != 0)
        throw StoreError(
            fmt::format("{}: cannot read the study file ({})", path, std::strerror(errno)));
    const std::string folder = std::filesystem::absolute(path).parent_path().string();
    std::error_code ec;
    const std::string wal = path + "-wal";
    const bool walHasData =
        std::filesystem::exists(wal, ec) && std::filesystem::file_size(wal, ec) > 0 && !ec;
    const bool canWrite = writableByThisUser(path, W_OK) && writableByThisUser(folder, W_OK | X_OK);
    // Immutable: SQLite takes no lock and needs no -shm (it could not create one in a read-only
    // folder), and it would ignore a -wal, so only when the -wal holds nothing.
    const bool immutable = !canWrite && !walHasData;
    std::unique_ptr<SQLite::Database> db;
    try {
        db = std::make_unique<SQLite::Database>(
            sqliteUri(path, immutable ? "mode=ro&immutable=1" : "mode=ro"),
            SQLite::OPEN_READONLY | SQLite::OPEN_URI);
        db->setBusyTimeout(5000);
        db->execAndGet("SELECT count(*) FROM sqlite_master");
    } catch (const SQLite::Exception& e) {
        if (walHasData && !canWrite)
            throw StoreError(fmt::format(
                "{}: cannot open the study read-only ({}): {} holds committed data that SQLite "
                "can read only with its {}-shm, which it cannot create in the read-only folder "
                "{}; copy the study with its -wal to a writable folder and open the copy",
                path, e.what(), wal, path, folder));
        throw StoreError(fmt::format("{}: not a readable study file ({})", path, e.what()));
    }
    if (const std::string problems = quickCheck(*db, std::chrono::seconds(10)); !problems.empty())
        throw StoreError(fmt::format("{}: the study file is damaged (SQLite integrity check: {}); "
                                     "{}",
                                     path, problems, recoveryHint(path)));
    StudyStore store(path, std::move(db), std::move(clock));
    store.readOnly_ = true;
    const int version = store.db_->execAndGet("PRAGMA user_version").getInt();
    if (version <= 0)
        throw StoreError(fmt::format("{}: not an Underfoot study (schema version {}; expected "
                                     "1 to {})",
                                     path, version, kSchemaVersion));
    if (version > kSchemaVersion)
        throw StoreError(fmt::format("{}: schema version {} was written by a newer Underfoot; "
                                     "this version reads up to {}",
                                     path, version, kSchemaVersion));
    if (version < kSchemaVersion)
        throw StoreError(fmt::format(
            "{}: the study has schema version {}; this Underfoot reads version {} and must "
            "migrate it first, which writes to the file, but it is opened read-only{}. Migrate "
            "a writable copy (any `underfoot study info --study COPY` does) and use the copy",
            path, version, kSchemaVersion,
            canWrite ? "" : " (the file or its folder is read-only for this user)"));
    try {
        store.loadProtocol(catalogue);
    } catch (const SQLite::Exception& e) {
        throw StoreError(fmt::format("{}: not a readable study file ({})", path, e.what()));
    }
    return store;
}

StudyStore StudyStore::openForReading(const std::string& path, Clock clock,
                                      const Catalogue& catalogue) {
    bool older = false;
    if (std::filesystem::exists(path) && ::access(path.c_str(), W_OK) == 0 &&
        ::access(std::filesystem::absolute(path).parent_path().c_str(), W_OK | X_OK) == 0) {
        // Only a writable study can be migrated; peek at its version without writing.
        try {
            SQLite::Database peek(sqliteUri(path, "mode=ro"),
                                  SQLite::OPEN_READONLY | SQLite::OPEN_URI);
            peek.setBusyTimeout(5000);
            const int v = peek.execAndGet("PRAGMA user_version").getInt();
            older = v > 0 && v < kSchemaVersion;
        } catch (const SQLite::Exception&) {
            // openReadOnly() says what is wrong with the file
        }
    }
    if (older) return open(path, std::move(clock), catalogue);
    return openReadOnly(path, std::move(clock), catalogue);
}

void StudyStore::writeFailed(const std::string& what, const std::exception& e) const {
    if (readOnly_)
        throw StoreError(fmt::format("{}: {} refused: the study was opened read-only (by a "
                                     "command that only reads it); nothing was written",
                                     path_, what));
    const auto* sq = dynamic_cast<const SQLite::Exception*>(&e);
    const int code = sq ? (sq->getErrorCode() & 0xff) : -1;
    const std::string folder = std::filesystem::absolute(path_).parent_path().string();
    std::string cause, todo;
    switch (code) {
    case SQLITE_FULL:
        cause = "the disk is full";
        todo = fmt::format("free space on the disk holding {}, then resume the session", folder);
        break;
    case SQLITE_READONLY:
        cause = "the study file is read-only for this user";
        todo = fmt::format("make {} writable by this user (and its folder {}, where SQLite "
                           "keeps {}-wal and -shm), then resume the session",
                           path_, folder, path_);
        break;
    case SQLITE_CANTOPEN:
        cause = fmt::format("SQLite cannot create its journal files {}-wal / -shm (is the "
                            "folder {} read-only?)",
                            path_, folder);
        todo = "make the folder writable by this user, then resume the session";
        break;
    case SQLITE_IOERR:
        cause = "an input/output error (disk full, removed or failing?)";
        todo = "check the disk, then resume the session";
        break;
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB:
        throw StoreError(fmt::format("{}: {} failed: the study file is damaged ({}); {}", path_,
                                     what, e.what(), recoveryHint(path_)));
    default:
        cause = "SQLite refused the write";
        todo = "resume the session once the cause is fixed";
        break;
    }
    throw StoreError(fmt::format("{}: {} failed: {} ({}). Every answer acknowledged before this "
                                 "one is safe in the file; {} (it resumes at the first "
                                 "unanswered trial)",
                                 path_, what, cause, e.what(), todo));
}

void StudyStore::checkpoint() {
    // wal_checkpoint(FULL) copies every committed frame into the main file and syncs it; a
    // deleted -wal then loses nothing acknowledged. A busy reader (the console) may keep some
    // frames in the WAL; they are committed durably there and copied at the next checkpoint.
    try {
        db_->execAndGet("PRAGMA wal_checkpoint(FULL)");
    } catch (const SQLite::Exception& e) {
        writeFailed("copying the answers into the study file (checkpoint)", e);
    }
}

void StudyStore::checkLease(std::int64_t participantId, const std::string& code) const {
    SQLite::Statement q(*db_, "SELECT token, pid, host, experimenter, since FROM session_leases "
                              "WHERE participant_id = ?");
    q.bind(1, participantId);
    if (!q.executeStep() || q.getColumn(0).getString() == leaseToken_) return;
    throw StoreError(fmt::format(
        "{}: participant '{}': the session lease is now held by process {} on host {} "
        "(experimenter '{}') since {}; this session was taken over and writes nothing more",
        path_, code, q.getColumn(1).getInt64(), q.getColumn(2).getString(),
        q.getColumn(3).getString(), q.getColumn(4).getString()));
}

void StudyStore::loadProtocol(const Catalogue& catalogue) {
    SQLite::Statement q(*db_, "SELECT text, source_name, hash FROM protocol WHERE id = 1");
    if (!q.executeStep()) throw StoreError(fmt::format("{}: the study has no protocol", path_));
    const std::string text = q.getColumn(0).getString();
    const std::string hash = q.getColumn(2).getString();
    if (sha256Hex(text) != hash)
        throw StoreError(fmt::format("{}: the stored protocol text does not match its stored "
                                     "hash (file damaged or edited by hand)",
                                     path_));
    try {
        protocol_ =
            std::make_unique<Protocol>(parseProtocol(text, q.getColumn(1).getString(), catalogue));
    } catch (const ProtocolError& e) {
        throw StoreError(
            fmt::format("{}: the stored protocol no longer validates:\n{}", path_, e.what()));
    }
}

StudyInfo StudyStore::info() const {
    SQLite::Statement q(*db_, "SELECT s.code, s.site, s.seed, s.created_at, s.app_version, "
                              "p.protocol_id, p.version, p.hash FROM study s, protocol p");
    if (!q.executeStep()) throw StoreError(fmt::format("{}: the study row is missing", path_));
    StudyInfo i;
    i.code = q.getColumn(0).getString();
    i.site = q.getColumn(1).getString();
    i.seed = fromDb(q.getColumn(2).getInt64());
    i.createdAt = q.getColumn(3).getString();
    i.appVersion = q.getColumn(4).getString();
    i.protocolId = q.getColumn(5).getString();
    i.protocolVersion = q.getColumn(6).getInt();
    i.protocolHash = q.getColumn(7).getString();
    i.schemaVersion = db_->execAndGet("PRAGMA user_version").getInt();
    return i;
}

void StudyStore::verifyProtocol(const Protocol& fileProtocol) const {
    if (fileProtocol.hash != protocol_->hash)
        throw StoreError(fmt::format(
            "{}: protocol file {} (sha256 {}) differs from the protocol this study was started "
            "with ({} version {}, sha256 {}); a changed protocol is refused for an existing "
            "study — create a new study for the new protocol",
            path_, fileProtocol.sourceName, fileProtocol.hash.substr(0, 12), protocol_->id,
            protocol_->version, protocol_->hash.substr(0, 12)));
}

void StudyStore::appendEvent(const std::string& kind, std::optional<std::int64_t> participantId,
                             std::optional<int> trialIndex, const std::string& detail) {
    SQLite::Statement q(*db_, "INSERT INTO events (at, kind, participant_id, trial_index, detail) "
                              "VALUES (?, ?, ?, ?, ?)");
    q.bind(1, now());
    q.bind(2, kind);
    if (participantId) q.bind(3, *participantId);
    if (trialIndex) q.bind(4, *trialIndex);
    q.bind(5, detail);
    q.exec();
}

void StudyStore::journal(const std::string& kind, const std::string& code,
                         std::optional<int> trialIndex, const std::string& detail) {
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    appendEvent(kind, code.empty() ? std::nullopt : std::optional(participantId(code)), trialIndex,
                detail);
    tx.commit();
}

std::vector<Event> StudyStore::events() const {
    std::vector<Event> out;
    SQLite::Statement q(*db_, "SELECT e.id, e.at, e.kind, p.code, e.trial_index, e.detail FROM "
                              "events e LEFT JOIN participants p ON p.id = e.participant_id "
                              "ORDER BY e.id");
    while (q.executeStep()) {
        Event e;
        e.id = q.getColumn(0).getInt64();
        e.at = q.getColumn(1).getString();
        e.kind = q.getColumn(2).getString();
        e.participant = columnText(q.getColumn(3));
        if (!q.getColumn(4).isNull()) e.trialIndex = q.getColumn(4).getInt();
        e.detail = q.getColumn(5).getString();
        out.push_back(std::move(e));
    }
    return out;
}

std::int64_t StudyStore::participantId(const std::string& code) const {
    SQLite::Statement q(*db_, "SELECT id FROM participants WHERE code = ?");
    q.bind(1, code);
    if (!q.executeStep())
        throw StoreError(
            fmt::format("{}: no participant '{}'; expected a registered code", path_, code));
    return q.getColumn(0).getInt64();
}

SQLite::Statement StudyStore::selectTrial(std::int64_t pid, const std::string& code, int trialIndex,
                                          const std::string& columns) const {
    SQLite::Statement q(*db_, "SELECT " + columns +
                                  " FROM trials WHERE participant_id = ? AND trial_index = ?");
    q.bind(1, pid);
    q.bind(2, trialIndex);
    if (!q.executeStep()) noSuchTrial(code, trialIndex);
    return q;
}

void StudyStore::noSuchTrial(const std::string& code, int trialIndex) const {
    throw StoreError(
        fmt::format("{}: participant '{}' has no trial {}", path_, code, trialIndex + 1));
}

namespace {
void readFields(SQLite::Database& db, ParticipantInfo& p) {
    SQLite::Statement q(db, "SELECT name, value FROM participant_fields WHERE participant_id = ?");
    q.bind(1, p.id);
    while (q.executeStep()) p.fields[q.getColumn(0).getString()] = q.getColumn(1).getString();
}
} // namespace

ParticipantInfo StudyStore::participant(const std::string& code) const {
    SQLite::Statement q(
        *db_, fmt::format("SELECT {} FROM participants WHERE code = ?", kParticipantColumns));
    q.bind(1, code);
    if (!q.executeStep())
        throw StoreError(
            fmt::format("{}: no participant '{}'; expected a registered code", path_, code));
    ParticipantInfo p = readParticipant(q);
    readFields(*db_, p);
    return p;
}

std::vector<ParticipantInfo> StudyStore::participants() const {
    std::vector<ParticipantInfo> out;
    SQLite::Statement q(
        *db_, fmt::format("SELECT {} FROM participants ORDER BY idx", kParticipantColumns));
    while (q.executeStep()) out.push_back(readParticipant(q));
    for (auto& p : out) readFields(*db_, p);
    return out;
}

std::vector<std::string>
StudyStore::checkParticipantFields(const std::map<std::string, std::string>& fields) const {
    std::vector<std::string> problems;
    for (const auto& [name, value] : fields) {
        const ParticipantField* f = protocol_->participantField(name);
        if (!f) {
            std::string known;
            for (const auto& pf : protocol_->participantFields)
                known += (known.empty() ? "" : ", ") + pf.id;
            problems.push_back(fmt::format("unknown participant field '{}'; expected one of: {}",
                                           name, known.empty() ? "(none declared)" : known));
            continue;
        }
        if (!f->options.empty() && !value.empty() &&
            std::find(f->options.begin(), f->options.end(), value) == f->options.end()) {
            std::string allowed;
            for (const auto& o : f->options) allowed += (allowed.empty() ? "" : ", ") + o;
            problems.push_back(fmt::format("participant field '{}' is '{}'; expected one of: {}",
                                           name, value, allowed));
        }
    }
    for (const auto& f : protocol_->participantFields) {
        const auto it = fields.find(f.id);
        if (f.required && (it == fields.end() || it->second.empty()))
            problems.push_back(
                fmt::format("participant field '{}' ({}) is required", f.id, f.label));
    }
    return problems;
}

std::vector<GroupCount> StudyStore::groupCounts() const {
    std::vector<GroupCount> out;
    for (const auto& g : protocol_->groups) out.push_back({g.id, 0, 0, 0, g.target});
    SQLite::Statement q(*db_, "SELECT group_id, status, count(*) FROM participants GROUP BY "
                              "group_id, status");
    while (q.executeStep()) {
        const std::string gid = q.getColumn(0).getString();
        const auto status = statusFromText(q.getColumn(1).getString());
        const int n = q.getColumn(2).getInt();
        auto it = std::find_if(out.begin(), out.end(),
                               [&](const GroupCount& c) { return c.groupId == gid; });
        if (it == out.end()) continue;
        if (status == ParticipantStatus::Dropped)
            it->dropped += n;
        else if (status == ParticipantStatus::Completed)
            it->completed += n;
        else
            it->active += n;
    }
    return out;
}

std::string StudyStore::nextGroup(int participantIndex) const {
    const auto counts = groupCounts();
    // Least-complete group: smallest share of its target (or smallest count without targets);
    // dropouts do not count, so their slot is filled again. Ties are broken at random from the
    // study seed and the participant index, so the order of groups is not predictable.
    std::vector<std::size_t> best;
    double bestShare = 0.0;
    for (std::size_t i = 0; i < counts.size(); ++i) {
        const int filled = counts[i].active + counts[i].completed;
        const double share = counts[i].target > 0 ? static_cast<double>(filled) / counts[i].target
                                                  : static_cast<double>(filled);
        if (best.empty() || share < bestShare - 1e-12) {
            best = {i};
            bestShare = share;
        } else if (std::fabs(share - bestShare) <= 1e-12) {
            best.push_back(i);
        }
    }
    Rng rng(deriveSeed(info().seed, {static_cast<std::uint64_t>(participantIndex), 3}));
    return counts[best[static_cast<std::size_t>(rng.below(best.size()))]].groupId;
}

std::vector<std::string> StudyStore::checkAnswer(const std::string& groupId,
                                                 const TrialAnswer& answer) const {
    std::vector<const Scale*> all;
    for (const auto& s : protocol_->questions.scales) all.push_back(&s);
    return checkAnswerScales(groupId, answer, all);
}

std::vector<std::string> StudyStore::checkAnswer(const std::string& groupId,
                                                 const TrialAnswer& answer,
                                                 const Stimulus& stimulus, int block) const {
    return checkAnswerScales(groupId, answer, askedScales(*protocol_, stimulus, block));
}

std::vector<std::string>
StudyStore::checkAnswerScales(const std::string& groupId, const TrialAnswer& answer,
                              const std::vector<const Scale*>& asked) const {
    std::vector<std::string> problems;
    const Questions& q = protocol_->questions;
    if (q.asksSurface()) {
        if (answer.answer.empty())
            problems.push_back("the surface answer is missing");
        else if (!q.surfaceOption(answer.answer))
            problems.push_back(
                fmt::format("'{}' is not an option of the answer list", answer.answer));
    } else if (!answer.answer.empty()) {
        problems.push_back("this protocol asks no surface question");
    }
    for (const Scale* scale : asked) {
        const auto it = answer.ratings.find(scale->id);
        if (it == answer.ratings.end())
            problems.push_back(fmt::format("the rating '{}' is missing", scale->id));
        else if (it->second < scale->min || it->second > scale->max)
            problems.push_back(fmt::format("rating '{}' is {}; expected {} to {}", scale->id,
                                           it->second, scale->min, scale->max));
    }
    for (const auto& [scaleId, value] : answer.ratings) {
        if (!q.scale(scaleId))
            problems.push_back(fmt::format("unknown scale '{}' (value {})", scaleId, value));
        else if (std::none_of(asked.begin(), asked.end(),
                              [&id = scaleId](const Scale* s) { return s->id == id; }))
            problems.push_back(fmt::format("scale '{}' is not asked in this trial", scaleId));
    }
    if (q.asksSoundscape(groupId)) {
        if (answer.soundscapeAnswer.empty())
            problems.push_back("the soundscape answer is missing");
        else if (!q.soundscapeOption(answer.soundscapeAnswer))
            problems.push_back(fmt::format("'{}' is not an option of the soundscape list",
                                           answer.soundscapeAnswer));
    } else if (!answer.soundscapeAnswer.empty()) {
        problems.push_back("the soundscape question is not asked to this group");
    }
    if (!answer.comment.empty() && !q.comment) problems.push_back("this protocol takes no comment");
    return problems;
}

ParticipantInfo StudyStore::registerParticipant(const NewParticipant& np) {
    return registerParticipant(np, {});
}

ParticipantInfo StudyStore::registerParticipant(const NewParticipant& np,
                                                const std::map<std::string, std::string>& fields) {
    if (const auto problems = checkParticipantFields(fields); !problems.empty()) {
        std::string all;
        for (const auto& s : problems) all += (all.empty() ? "" : "; ") + s;
        throw StoreError(fmt::format("participant {}: {}", np.code, all));
    }
    if (np.code.empty() || np.code.size() > 32 ||
        !std::all_of(np.code.begin(), np.code.end(), [](char c) {
            return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
        }))
        throw StoreError(fmt::format("participant code '{}': expected 1 to 32 letters, digits, "
                                     "'_' or '-' (a pseudonym, never a name)",
                                     np.code));
    if (np.age && (*np.age < 0 || *np.age > 130))
        throw StoreError(
            fmt::format("participant {}: age {} is out of range 0-130", np.code, *np.age));
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    {
        SQLite::Statement exists(*db_, "SELECT 1 FROM participants WHERE code = ?");
        exists.bind(1, np.code);
        if (exists.executeStep())
            throw StoreError(
                fmt::format("{}: participant '{}' is already registered", path_, np.code));
    }
    const int index = db_->execAndGet("SELECT count(*) FROM participants").getInt();
    std::string groupId;
    Assignment assignment = Assignment::Balanced;
    if (np.groupOverride) {
        if (!protocol_->group(*np.groupOverride))
            throw StoreError(fmt::format("group override '{}' is not a group of protocol '{}'",
                                         *np.groupOverride, protocol_->id));
        if (np.overrideReason.empty())
            throw StoreError("a group override needs a reason (it is journaled)");
        groupId = *np.groupOverride;
        assignment = Assignment::Override;
    } else {
        groupId = nextGroup(index);
    }
    const std::uint64_t seed = info().seed;
    const std::vector<PlannedTrial> plan = generatePlan(*protocol_, groupId, seed, index);
    const std::string at = now();
    SQLite::Statement ins(*db_, "INSERT INTO participants (code, idx, age, gender, shoes, hearing, "
                                "group_id, assignment, override_reason, status, seed, "
                                "registered_at, simulated) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, "
                                "'registered', ?, ?, ?)");
    ins.bind(1, np.code);
    ins.bind(2, index);
    if (np.age) ins.bind(3, *np.age);
    ins.bind(4, np.gender);
    ins.bind(5, np.shoes);
    ins.bind(6, np.hearing);
    ins.bind(7, groupId);
    ins.bind(8, assignment == Assignment::Override ? "override" : "balanced");
    ins.bind(9, np.overrideReason);
    ins.bind(10, toDb(participantSeed(seed, index)));
    ins.bind(11, at);
    ins.bind(12, np.simulated ? 1 : 0);
    ins.exec();
    const std::int64_t pid = db_->getLastInsertRowid();
    SQLite::Statement field(*db_, "INSERT INTO participant_fields (participant_id, name, value) "
                                  "VALUES (?, ?, ?)");
    std::string fieldsText;
    for (const auto& [name, value] : fields) {
        field.reset();
        field.bind(1, pid);
        field.bind(2, name);
        field.bind(3, value);
        field.exec();
        fieldsText += fmt::format("{}{}={}", fieldsText.empty() ? "" : " ", name, value);
    }
    SQLite::Statement trial(*db_, "INSERT INTO trials (participant_id, trial_index, block, "
                                  "practice, stimulus_id, stimulus, repetition, break_after, "
                                  "planned_seed) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)");
    for (const auto& t : plan) {
        trial.reset();
        trial.bind(1, pid);
        trial.bind(2, t.index);
        trial.bind(3, t.block);
        trial.bind(4, t.practice ? 1 : 0);
        trial.bind(5, t.stimulus.id);
        trial.bind(6, stimulusToToml(t.stimulus));
        trial.bind(7, t.repetition);
        trial.bind(8, t.breakAfter ? 1 : 0);
        trial.bind(9, toDb(t.plannedSeed));
        trial.exec();
    }
    appendEvent(
        "participant_registered", pid, std::nullopt,
        jsonObject({{"code", np.code},
                    {"index", std::to_string(index)},
                    {"group", groupId},
                    {"assignment", assignment == Assignment::Override ? "override" : "balanced"},
                    {"reason", np.overrideReason},
                    {"fields", fieldsText},
                    {"simulated", np.simulated ? "1" : "0"},
                    {"trials", std::to_string(plan.size())}}));
    tx.commit();
    return participant(np.code);
}

void StudyStore::dropParticipant(const std::string& code, const std::string& reason) {
    if (reason.empty()) throw StoreError("dropping a participant needs a reason (journaled)");
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "UPDATE participants SET status = 'dropped' WHERE id = ?");
    q.bind(1, pid);
    q.exec();
    appendEvent("participant_dropped", pid, std::nullopt, jsonObject({{"reason", reason}}));
    tx.commit();
}

int StudyStore::startSession(const std::string& code, const SessionSettings& settings) {
    if (readOnly_)
        throw StoreError(fmt::format("{}: participant '{}': a session cannot start on a study "
                                     "opened read-only; open it for writing",
                                     path_, code));
    try {
        SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
        const ParticipantInfo p = participant(code);
        if (p.status == ParticipantStatus::Dropped)
            throw StoreError(
                fmt::format("participant '{}' dropped out; a session cannot start", code));
        if (p.status == ParticipantStatus::Completed)
            throw StoreError(fmt::format("participant '{}' has completed every trial", code));
        SQLite::Statement n(*db_, "SELECT coalesce(max(number), 0) + 1 FROM sessions WHERE "
                                  "participant_id = ?");
        n.bind(1, p.id);
        n.executeStep();
        const int number = n.getColumn(0).getInt();
        // The participant's lease (issue #16): one live session per participant.
        const std::string host = hostName();
        const std::int64_t myPid = ::getpid();
        {
            SQLite::Statement lease(*db_, "SELECT token, pid, host, experimenter, since, "
                                          "session_number FROM session_leases WHERE "
                                          "participant_id = ?");
            lease.bind(1, p.id);
            if (lease.executeStep() && lease.getColumn(0).getString() != leaseToken_) {
                const std::int64_t holderPid = lease.getColumn(1).getInt64();
                const std::string holderHost = lease.getColumn(2).getString();
                const bool sameProcess = holderHost == host && holderPid == myPid;
                const bool gone = holderHost == host && processIsGone(holderPid);
                if (!sameProcess && !gone && !settings.takeOver)
                    throw StoreError(fmt::format(
                        "{}: participant '{}' is in session {} held by process {} on host {} "
                        "(experimenter '{}') since {}; one session per participant at a time. If "
                        "that session crashed or its machine is gone, take the session over with "
                        "`underfoot session ... --take-over`",
                        path_, code, lease.getColumn(5).getInt(), holderPid, holderHost,
                        lease.getColumn(3).getString(), lease.getColumn(4).getString()));
                appendEvent(sameProcess || gone ? "lease_recovered" : "lease_taken_over", p.id,
                            std::nullopt,
                            jsonObject({{"pid", std::to_string(holderPid)},
                                        {"host", holderHost},
                                        {"experimenter", lease.getColumn(3).getString()},
                                        {"since", lease.getColumn(4).getString()},
                                        {"session", std::to_string(lease.getColumn(5).getInt())}}));
            }
        }
        SQLite::Statement take(*db_,
                               "INSERT OR REPLACE INTO session_leases (participant_id, token, "
                               "pid, host, experimenter, session_number, since) VALUES "
                               "(?, ?, ?, ?, ?, ?, ?)");
        take.bind(1, p.id);
        take.bind(2, leaseToken_);
        take.bind(3, myPid);
        take.bind(4, host);
        take.bind(5, settings.experimenter);
        take.bind(6, number);
        take.bind(7, now());
        take.exec();
        SQLite::Statement ins(*db_, "INSERT INTO sessions (participant_id, number, group_id, seed, "
                                    "app_version, audio_config, sensor_config, experimenter, "
                                    "started_at, sound_played) VALUES (?, ?, ?, ?, ?, ?, ?, ?, "
                                    "?, ?)");
        ins.bind(1, p.id);
        ins.bind(2, number);
        ins.bind(3, p.groupId);
        ins.bind(4, toDb(participantSeed(info().seed, p.index)));
        ins.bind(5, settings.appVersion);
        ins.bind(6, settings.audioConfig);
        ins.bind(7, settings.sensorConfig);
        ins.bind(8, settings.experimenter);
        ins.bind(9, now());
        if (settings.soundPlayed) ins.bind(10, *settings.soundPlayed ? 1 : 0);
        ins.exec();
        SQLite::Statement st(*db_, "UPDATE participants SET status = 'active' WHERE id = ?");
        st.bind(1, p.id);
        st.exec();
        appendEvent("session_started", p.id, std::nullopt,
                    jsonObject({{"session", std::to_string(number)},
                                {"experimenter", settings.experimenter},
                                {"audio", settings.audioConfig},
                                {"sensor", settings.sensorConfig},
                                {"sound", !settings.soundPlayed   ? "unknown"
                                          : *settings.soundPlayed ? "played"
                                                                  : "none (data entry)"},
                                {"app_version", settings.appVersion}}));
        tx.commit();
        return number;
    } catch (const SQLite::Exception& e) {
        writeFailed(fmt::format("starting a session of participant '{}'", code), e);
    }
}

std::vector<SessionRecord> StudyStore::sessions(const std::string& code) const {
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "SELECT number, experimenter, audio_config, sensor_config, "
                              "started_at, ended_at, outcome, sound_played FROM sessions WHERE "
                              "participant_id = ? ORDER BY number");
    q.bind(1, pid);
    std::vector<SessionRecord> out;
    while (q.executeStep()) {
        SessionRecord r;
        r.number = q.getColumn(0).getInt();
        r.experimenter = q.getColumn(1).getString();
        r.audioConfig = q.getColumn(2).getString();
        r.sensorConfig = q.getColumn(3).getString();
        r.startedAt = q.getColumn(4).getString();
        r.endedAt = columnText(q.getColumn(5));
        r.outcome = columnText(q.getColumn(6));
        if (!q.getColumn(7).isNull()) r.soundPlayed = q.getColumn(7).getInt() != 0;
        out.push_back(std::move(r));
    }
    return out;
}

void StudyStore::endSession(const std::string& code, int sessionNumber, bool completed) {
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "UPDATE sessions SET ended_at = ?, outcome = ? WHERE "
                              "participant_id = ? AND number = ?");
    q.bind(1, now());
    q.bind(2, completed ? "completed" : "interrupted");
    q.bind(3, pid);
    q.bind(4, sessionNumber);
    q.exec();
    if (completed) {
        SQLite::Statement st(*db_, "UPDATE participants SET status = 'completed' WHERE id = ?");
        st.bind(1, pid);
        st.exec();
    }
    SQLite::Statement release(*db_, "DELETE FROM session_leases WHERE participant_id = ? AND "
                                    "token = ?");
    release.bind(1, pid);
    release.bind(2, leaseToken_);
    release.exec();
    appendEvent("session_ended", pid, std::nullopt,
                jsonObject({{"session", std::to_string(sessionNumber)},
                            {"outcome", completed ? "completed" : "interrupted"}}));
    tx.commit();
}

void StudyStore::markCompleted(const std::string& code) {
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const ParticipantInfo p = participant(code);
    if (p.status == ParticipantStatus::Completed) return;
    if (p.status == ParticipantStatus::Dropped)
        throw StoreError(fmt::format("participant '{}' dropped out; not marked completed", code));
    if (firstUnanswered(code))
        throw StoreError(fmt::format("participant '{}' still has unanswered trials", code));
    SQLite::Statement st(*db_, "UPDATE participants SET status = 'completed' WHERE id = ?");
    st.bind(1, p.id);
    st.exec();
    appendEvent("participant_completed", p.id, std::nullopt,
                jsonObject({{"note", "every trial answered; the session had not been closed"}}));
    tx.commit();
}

namespace {
constexpr const char* kTrialColumns =
    "t.id, p.code, t.trial_index, t.block, t.practice, t.stimulus, t.repetition, t.planned_seed, "
    "t.render_seed, t.grf_recording, t.session_number, t.started_at, t.answered_at, "
    "t.response_time_s, t.answer, t.soundscape_answer, t.comment, t.excluded, "
    "t.exclusion_reason, t.break_after, t.replays, t.laps_done, t.audio_sample_rate_hz, "
    "t.audio_block_size, t.audio_frames, t.audio_xruns, t.audio_average_load_percent, "
    "t.audio_max_load_percent, t.audio_max_block_ms, t.audio_dropped_grf_frames, t.sensor_log, "
    "t.interruptions, t.interruption_reason";

TrialRecord readTrial(SQLite::Database& db, SQLite::Statement& q) {
    TrialRecord r;
    const std::int64_t trialId = q.getColumn(0).getInt64();
    r.participant = q.getColumn(1).getString();
    r.index = q.getColumn(2).getInt();
    r.block = q.getColumn(3).getInt();
    r.practice = q.getColumn(4).getInt() != 0;
    try {
        r.stimulus = stimulusFromToml(q.getColumn(5).getString());
    } catch (const std::runtime_error& e) { // a damaged file (found by fuzz_study_db)
        throw StoreError(fmt::format("{}: participant '{}' trial {}: {}; the study file is "
                                     "damaged",
                                     db.getFilename(), r.participant, r.index + 1, e.what()));
    }
    r.repetition = q.getColumn(6).getInt();
    r.plannedSeed = fromDb(q.getColumn(7).getInt64());
    if (!q.getColumn(8).isNull()) r.renderSeed = fromDb(q.getColumn(8).getInt64());
    if (!q.getColumn(9).isNull()) r.grfRecording = q.getColumn(9).getString();
    if (!q.getColumn(10).isNull()) r.sessionNumber = q.getColumn(10).getInt();
    r.startedAt = columnText(q.getColumn(11));
    r.answeredAt = columnText(q.getColumn(12));
    r.answered = !r.answeredAt.empty();
    if (!q.getColumn(13).isNull()) r.responseTimeS = q.getColumn(13).getDouble();
    r.answer.answer = columnText(q.getColumn(14));
    r.answer.soundscapeAnswer = columnText(q.getColumn(15));
    r.answer.comment = columnText(q.getColumn(16));
    r.excluded = q.getColumn(17).getInt() != 0;
    r.exclusionReason = q.getColumn(18).getString();
    r.breakAfter = q.getColumn(19).getInt() != 0;
    r.replays = q.getColumn(20).getInt();
    r.lapsDone = q.getColumn(21).getInt();
    if (!q.getColumn(22).isNull()) {
        TrialAudioStats a;
        a.sampleRateHz = q.getColumn(22).getDouble();
        a.blockSize = q.getColumn(23).getInt();
        a.frames = fromDb(q.getColumn(24).getInt64());
        a.xruns = fromDb(q.getColumn(25).getInt64());
        a.averageLoadPercent = q.getColumn(26).getDouble();
        a.maxLoadPercent = q.getColumn(27).getDouble();
        a.maxBlockMs = q.getColumn(28).getDouble();
        a.droppedGrfFrames = fromDb(q.getColumn(29).getInt64());
        r.audio = a;
    }
    if (!q.getColumn(30).isNull()) r.sensorLog = q.getColumn(30).getString();
    r.interruptions = q.getColumn(31).getInt();
    r.interruptionReason = q.getColumn(32).getString();
    if (r.answered) {
        SQLite::Statement rq(db, "SELECT scale, value FROM ratings WHERE trial_id = ?");
        rq.bind(1, trialId);
        while (rq.executeStep())
            r.answer.ratings[rq.getColumn(0).getString()] = rq.getColumn(1).getInt();
    }
    return r;
}
} // namespace

std::vector<TrialRecord> StudyStore::trials(const std::string& code) const {
    const std::int64_t pid = participantId(code);
    std::vector<TrialRecord> out;
    SQLite::Statement q(*db_, fmt::format("SELECT {} FROM trials t JOIN participants p ON p.id = "
                                          "t.participant_id WHERE t.participant_id = ? ORDER BY "
                                          "t.trial_index",
                                          kTrialColumns));
    q.bind(1, pid);
    while (q.executeStep()) out.push_back(readTrial(*db_, q));
    return out;
}

TrialRecord StudyStore::trial(const std::string& code, int trialIndex) const {
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, fmt::format("SELECT {} FROM trials t JOIN participants p ON p.id = "
                                          "t.participant_id WHERE t.participant_id = ? AND "
                                          "t.trial_index = ?",
                                          kTrialColumns));
    q.bind(1, pid);
    q.bind(2, trialIndex);
    if (!q.executeStep()) noSuchTrial(code, trialIndex);
    return readTrial(*db_, q);
}

std::optional<int> StudyStore::firstUnanswered(const std::string& code) const {
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "SELECT min(trial_index) FROM trials WHERE participant_id = ? AND "
                              "answered_at IS NULL");
    q.bind(1, pid);
    q.executeStep();
    if (q.getColumn(0).isNull()) return std::nullopt;
    return q.getColumn(0).getInt();
}

void StudyStore::markTrialStarted(const std::string& code, int trialIndex, int sessionNumber,
                                  std::uint64_t renderSeed,
                                  const std::optional<std::string>& grfRecording) {
    try {
        SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
        const std::int64_t pid = participantId(code);
        checkLease(pid, code);
        SQLite::Statement check = selectTrial(pid, code, trialIndex, "answered_at, started_at");
        if (!check.getColumn(0).isNull())
            throw StoreError(
                fmt::format("participant '{}' trial {} is already answered", code, trialIndex + 1));
        const bool restarted = !check.getColumn(1).isNull();
        // A restarted trial's earlier sensor log and audio figures belong to the earlier
        // presentation.
        SQLite::Statement q(*db_,
                            "UPDATE trials SET started_at = ?, render_seed = ?, grf_recording = "
                            "?, session_number = ?, sensor_log = NULL, audio_sample_rate_hz = "
                            "NULL, audio_block_size = NULL, audio_frames = NULL, audio_xruns = "
                            "NULL, audio_average_load_percent = NULL, audio_max_load_percent = "
                            "NULL, audio_max_block_ms = NULL, audio_dropped_grf_frames = NULL "
                            "WHERE participant_id = ? AND trial_index = ?");
        q.bind(1, now());
        q.bind(2, toDb(renderSeed));
        if (grfRecording) q.bind(3, *grfRecording);
        q.bind(4, sessionNumber);
        q.bind(5, pid);
        q.bind(6, trialIndex);
        q.exec();
        appendEvent(restarted ? "trial_restarted" : "trial_started", pid, trialIndex,
                    jsonObject({{"session", std::to_string(sessionNumber)},
                                {"render_seed", std::to_string(renderSeed)},
                                {"grf", grfRecording.value_or("")}}));
        tx.commit();
    } catch (const SQLite::Exception& e) {
        writeFailed(
            fmt::format("recording the start of participant '{}' trial {}", code, trialIndex + 1),
            e);
    }
}

void StudyStore::commitAnswer(const std::string& code, int trialIndex, const TrialAnswer& answer,
                              std::optional<double> responseTimeS) {
    if (responseTimeS && (!std::isfinite(*responseTimeS) || *responseTimeS < 0))
        throw StoreError(fmt::format("participant '{}' trial {}: response time must be a finite "
                                     "number >= 0",
                                     code, trialIndex + 1));
    try {
        SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
        const ParticipantInfo p = participant(code);
        checkLease(p.id, code);
        SQLite::Statement cur = selectTrial(
            p.id, code, trialIndex, "id, started_at, answered_at, stimulus, block, laps_done");
        const Stimulus trialStimulus = stimulusFromToml(cur.getColumn(3).getString());
        if (const auto problems =
                checkAnswer(p.groupId, answer, trialStimulus, cur.getColumn(4).getInt());
            !problems.empty()) {
            std::string all;
            for (const auto& s : problems) all += (all.empty() ? "" : "; ") + s;
            throw StoreError(
                fmt::format("participant '{}' trial {}: {}", code, trialIndex + 1, all));
        }
        if (const int laps = protocol_->laps.total();
            laps > 0 && !cur.getColumn(1).isNull() && cur.getColumn(5).getInt() < laps)
            throw StoreError(
                fmt::format("participant '{}' trial {}: {} of {} laps walked; expected "
                            "every lap (baseline and feedback) before the questions",
                            code, trialIndex + 1, cur.getColumn(5).getInt(), laps));
        const std::int64_t trialId = cur.getColumn(0).getInt64();
        if (cur.getColumn(1).isNull())
            throw StoreError(fmt::format("participant '{}' trial {} has not started; expected its "
                                         "stimulus to be played first",
                                         code, trialIndex + 1));
        const bool changing = !cur.getColumn(2).isNull();
        if (changing) {
            if (protocol_->lock == LockRule::OnAnswer)
                throw StoreError(fmt::format("participant '{}' trial {}: answers are locked once "
                                             "given (protocol rule lock = \"answer\")",
                                             code, trialIndex + 1));
            SQLite::Statement later(*db_, "SELECT 1 FROM trials WHERE participant_id = ? AND "
                                          "trial_index > ? AND started_at IS NOT NULL");
            later.bind(1, p.id);
            later.bind(2, trialIndex);
            if (later.executeStep())
                throw StoreError(
                    fmt::format("participant '{}' trial {}: the answer is locked because "
                                "the next trial has started",
                                code, trialIndex + 1));
        }
        SQLite::Statement q(*db_,
                            "UPDATE trials SET answered_at = ?, response_time_s = ?, answer = ?, "
                            "soundscape_answer = ?, comment = ? WHERE id = ?");
        q.bind(1, now());
        if (responseTimeS) q.bind(2, *responseTimeS);
        if (!answer.answer.empty()) q.bind(3, answer.answer);
        if (!answer.soundscapeAnswer.empty()) q.bind(4, answer.soundscapeAnswer);
        if (!answer.comment.empty()) q.bind(5, answer.comment);
        q.bind(6, trialId);
        q.exec();
        SQLite::Statement del(*db_, "DELETE FROM ratings WHERE trial_id = ?");
        del.bind(1, trialId);
        del.exec();
        SQLite::Statement rate(*db_,
                               "INSERT INTO ratings (trial_id, scale, value) VALUES (?, ?, ?)");
        std::string ratingsText;
        for (const auto& [scale, value] : answer.ratings) {
            rate.reset();
            rate.bind(1, trialId);
            rate.bind(2, scale);
            rate.bind(3, value);
            rate.exec();
            ratingsText += fmt::format("{}{}={}", ratingsText.empty() ? "" : " ", scale, value);
        }
        appendEvent(changing ? "answer_changed" : "answered", p.id, trialIndex,
                    jsonObject({{"answer", answer.answer},
                                {"ratings", ratingsText},
                                {"soundscape", answer.soundscapeAnswer},
                                {"comment", answer.comment},
                                {"response_time_s",
                                 responseTimeS ? fmt::format("{:.3f}", *responseTimeS) : ""}}));
        tx.commit();
    } catch (const SQLite::Exception& e) {
        writeFailed(
            fmt::format("saving the answer of participant '{}' trial {}", code, trialIndex + 1), e);
    }
    // Committed with synchronous=FULL: the answer is durable in the WAL from here on. A failed
    // checkpoint must not look like a lost answer (the caller would ask for it again and store
    // it as a change), so it is reported as what it is.
    try {
        checkpoint();
    } catch (const StoreError& e) {
        throw AnswerSavedButNotCopied(fmt::format(
            "participant '{}' trial {}: the answer IS saved (in {}-wal; keep that file beside the "
            "study and do not delete it), but copying it into the study file then failed: {}",
            code, trialIndex + 1, path_, e.what()));
    }
}

void StudyStore::recordReplay(const std::string& code, int trialIndex) {
    if (!protocol_->clips.replay)
        throw StoreError(fmt::format("participant '{}' trial {}: the protocol does not allow "
                                     "replays ([clips] replay = false)",
                                     code, trialIndex + 1));
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement cur = selectTrial(pid, code, trialIndex, "started_at, answered_at, replays");
    if (cur.getColumn(0).isNull())
        throw StoreError(fmt::format("participant '{}' trial {}: replay before the first "
                                     "presentation; expected play() first",
                                     code, trialIndex + 1));
    if (!cur.getColumn(1).isNull())
        throw StoreError(
            fmt::format("participant '{}' trial {} is already answered", code, trialIndex + 1));
    const int replays = cur.getColumn(2).getInt() + 1;
    SQLite::Statement q(*db_, "UPDATE trials SET replays = ? WHERE participant_id = ? AND "
                              "trial_index = ?");
    q.bind(1, replays);
    q.bind(2, pid);
    q.bind(3, trialIndex);
    q.exec();
    appendEvent("clip_replayed", pid, trialIndex,
                jsonObject({{"replays", std::to_string(replays)}}));
    tx.commit();
}

void StudyStore::recordLap(const std::string& code, int trialIndex, int lap) {
    const Laps& laps = protocol_->laps;
    if (lap < 1 || lap > laps.total())
        throw StoreError(fmt::format("participant '{}' trial {}: lap {} is outside 1 to {}", code,
                                     trialIndex + 1, lap, laps.total()));
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement cur =
        selectTrial(pid, code, trialIndex, "started_at, answered_at, laps_done");
    if (cur.getColumn(0).isNull() || !cur.getColumn(1).isNull())
        throw StoreError(fmt::format("participant '{}' trial {}: laps are recorded between the "
                                     "start of a condition and its answer",
                                     code, trialIndex + 1));
    if (cur.getColumn(2).getInt() != lap - 1)
        throw StoreError(fmt::format("participant '{}' trial {}: lap {} completed after {} laps; "
                                     "expected lap {}",
                                     code, trialIndex + 1, lap, cur.getColumn(2).getInt(),
                                     cur.getColumn(2).getInt() + 1));
    SQLite::Statement q(*db_, "UPDATE trials SET laps_done = ? WHERE participant_id = ? AND "
                              "trial_index = ?");
    q.bind(1, lap);
    q.bind(2, pid);
    q.bind(3, trialIndex);
    q.exec();
    appendEvent("lap_completed", pid, trialIndex,
                jsonObject({{"lap", std::to_string(lap)},
                            {"sound", laps.silent(lap) ? "silent baseline" : "feedback"}}));
    tx.commit();
}

void StudyStore::setSensorLog(const std::string& code, int trialIndex,
                              const std::string& sensorLog) {
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "UPDATE trials SET sensor_log = ? WHERE participant_id = ? AND "
                              "trial_index = ? AND started_at IS NOT NULL");
    q.bind(1, sensorLog);
    q.bind(2, pid);
    q.bind(3, trialIndex);
    if (q.exec() != 1)
        throw StoreError(fmt::format("{}: participant '{}' has no started trial {}", path_, code,
                                     trialIndex + 1));
    tx.commit();
}

void StudyStore::recordTrialAudio(const std::string& code, int trialIndex,
                                  const TrialAudioStats& a) {
    for (const double v : {a.sampleRateHz, a.averageLoadPercent, a.maxLoadPercent, a.maxBlockMs})
        if (!std::isfinite(v) || v < 0)
            throw StoreError(fmt::format("participant '{}' trial {}: audio figures must be finite "
                                         "numbers >= 0",
                                         code, trialIndex + 1));
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "UPDATE trials SET audio_sample_rate_hz = ?, audio_block_size = ?, "
                              "audio_frames = ?, audio_xruns = ?, audio_average_load_percent = ?, "
                              "audio_max_load_percent = ?, audio_max_block_ms = ?, "
                              "audio_dropped_grf_frames = ? WHERE participant_id = ? AND "
                              "trial_index = ?");
    q.bind(1, a.sampleRateHz);
    q.bind(2, a.blockSize);
    q.bind(3, toDb(a.frames));
    q.bind(4, toDb(a.xruns));
    q.bind(5, a.averageLoadPercent);
    q.bind(6, a.maxLoadPercent);
    q.bind(7, a.maxBlockMs);
    q.bind(8, toDb(a.droppedGrfFrames));
    q.bind(9, pid);
    q.bind(10, trialIndex);
    if (q.exec() != 1) noSuchTrial(code, trialIndex);
    tx.commit();
}

void StudyStore::markTrialInterrupted(const std::string& code, int trialIndex,
                                      const std::string& reason) {
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "UPDATE trials SET interruptions = interruptions + 1, "
                              "interruption_reason = ? WHERE participant_id = ? AND trial_index = "
                              "? AND answered_at IS NULL");
    q.bind(1, reason);
    q.bind(2, pid);
    q.bind(3, trialIndex);
    if (q.exec() != 1)
        throw StoreError(fmt::format("{}: participant '{}' has no unanswered trial {}", path_, code,
                                     trialIndex + 1));
    appendEvent("trial_interrupted", pid, trialIndex, jsonObject({{"reason", reason}}));
    tx.commit();
}

void StudyStore::setExcluded(const std::string& code, int trialIndex, bool excluded,
                             const std::string& reason) {
    if (excluded && reason.empty())
        throw StoreError("excluding a trial needs a reason (journaled and exported)");
    SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::int64_t pid = participantId(code);
    SQLite::Statement q(*db_, "UPDATE trials SET excluded = ?, exclusion_reason = ? WHERE "
                              "participant_id = ? AND trial_index = ?");
    q.bind(1, excluded ? 1 : 0);
    q.bind(2, excluded ? reason : std::string());
    q.bind(3, pid);
    q.bind(4, trialIndex);
    if (q.exec() != 1) noSuchTrial(code, trialIndex);
    appendEvent(excluded ? "trial_excluded" : "trial_included", pid, trialIndex,
                jsonObject({{"reason", reason}}));
    tx.commit();
}

std::map<std::string, std::pair<int, int>> StudyStore::progressCounts() const {
    std::map<std::string, std::pair<int, int>> out;
    SQLite::Statement q(*db_,
                        "SELECT p.code, count(t.answered_at), count(t.id) FROM participants p "
                        "LEFT JOIN trials t ON t.participant_id = p.id GROUP BY p.id");
    while (q.executeStep())
        out[q.getColumn(0).getString()] = {q.getColumn(1).getInt(), q.getColumn(2).getInt()};
    return out;
}

ReplayInfo StudyStore::trialForReplay(const std::string& code, int trialIndex) const {
    const TrialRecord t = trial(code, trialIndex);
    if (!t.renderSeed || !t.sessionNumber)
        throw StoreError(fmt::format("participant '{}' trial {} was never presented; nothing to "
                                     "replay",
                                     code, trialIndex + 1));
    ReplayInfo r;
    const StudyInfo i = info();
    r.study = i.code;
    r.protocolHash = i.protocolHash;
    r.participant = code;
    r.trialIndex = trialIndex;
    r.stimulus = t.stimulus;
    r.renderSeed = *t.renderSeed;
    r.grfRecording = t.grfRecording;
    SQLite::Statement q(*db_, "SELECT audio_config, sensor_config FROM sessions WHERE "
                              "participant_id = ? AND number = ?");
    q.bind(1, participantId(code));
    q.bind(2, *t.sessionNumber);
    if (q.executeStep()) {
        r.audioConfig = q.getColumn(0).getString();
        r.sensorConfig = q.getColumn(1).getString();
    }
    return r;
}

} // namespace underfoot::experiment
