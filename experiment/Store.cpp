// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/Store.h"
#include "experiment/StoreInternal.h"

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

using namespace store_detail;

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

/// Refuses a damaged study file before anything is written to it (or read from it).
void refuseDamaged(SQLite::Database& db, const std::string& path) {
    if (const std::string problems = quickCheck(db, std::chrono::seconds(10)); !problems.empty())
        throw StoreError(fmt::format("{}: the study file is damaged (SQLite integrity check: {}); "
                                     "{}",
                                     path, problems, recoveryHint(path)));
}

/// The schema version of an opened study file; refuses a file that is not a study (0 or less).
int studySchemaVersion(SQLite::Database& db, const std::string& path) {
    const int version = db.execAndGet("PRAGMA user_version").getInt();
    if (version <= 0)
        throw StoreError(fmt::format("{}: not an Underfoot study (schema version {}; expected "
                                     "1 to {})",
                                     path, version, kSchemaVersion));
    return version;
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
    // ours (a negative one used to index the migrations at -1).
    if (version < 0)
        throw StoreError(fmt::format("{}: schema version {} is not one Underfoot ever wrote "
                                     "(expected 1 to {}); the file is damaged or not a study",
                                     path_, version, kSchemaVersion));
    for (int v = version; v < kSchemaVersion; ++v) {
        SQLite::Transaction tx(*db_, SQLite::TransactionBehavior::IMMEDIATE);
        db_->exec(migration(v));
        db_->exec(fmt::format("PRAGMA user_version = {}", v + 1));
        if (version > 0) // a real migration of an existing study is journaled
            appendEvent(JournalEvent::SchemaMigrated, std::nullopt, std::nullopt,
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
    store.appendEvent(JournalEvent::StudyCreated, std::nullopt, std::nullopt,
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
    // fail to create its -wal/-shm files, with a misleading message).
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
    refuseDamaged(*db, path);
    StudyStore store(path, std::move(db), std::move(clock));
    studySchemaVersion(*store.db_, path);
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
    refuseDamaged(*db, path);
    StudyStore store(path, std::move(db), std::move(clock));
    store.readOnly_ = true;
    const int version = studySchemaVersion(*store.db_, path);
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

} // namespace underfoot::experiment
