// SPDX-License-Identifier: GPL-3.0-or-later
// An answer committed to the write-ahead log whose checkpoint into the study file then
// fails is stored; the store says so (AnswerSavedButNotCopied) and the session moves on instead of
// asking for the answer again (which would have stored it a second time, as a changed answer).
//
// The fault is injected with a SQLite VFS that wraps the default one and fails every write and
// sync of the main database file while armed; the WAL and shared-memory files still work, which
// is the state of a study whose main file's disk region fails after the commit.
#include "TestSupport.h"
#include "experiment/Session.h"
#include "experiment/Store.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <atomic>
#include <cstring>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

namespace {

std::atomic<bool> gFailMainFile{false};
std::atomic<int> gRefusedWrites{0};
sqlite3_vfs* gReal = nullptr;

/// Our file object; the wrapped VFS's own file object follows it in the same allocation.
struct FaultFile {
    sqlite3_file base;
    sqlite3_file* real;
    bool mainDb;
};

sqlite3_file* real(sqlite3_file* f) {
    return reinterpret_cast<FaultFile*>(f)->real;
}
bool failing(sqlite3_file* f) {
    return reinterpret_cast<FaultFile*>(f)->mainDb && gFailMainFile.load();
}

int xClose(sqlite3_file* f) {
    return real(f)->pMethods ? real(f)->pMethods->xClose(real(f)) : SQLITE_OK;
}
int xRead(sqlite3_file* f, void* p, int n, sqlite3_int64 off) {
    return real(f)->pMethods->xRead(real(f), p, n, off);
}
int xWrite(sqlite3_file* f, const void* p, int n, sqlite3_int64 off) {
    if (failing(f)) {
        ++gRefusedWrites;
        return SQLITE_IOERR_WRITE;
    }
    return real(f)->pMethods->xWrite(real(f), p, n, off);
}
int xTruncate(sqlite3_file* f, sqlite3_int64 size) {
    if (failing(f)) return SQLITE_IOERR_TRUNCATE;
    return real(f)->pMethods->xTruncate(real(f), size);
}
int xSync(sqlite3_file* f, int flags) {
    if (failing(f)) return SQLITE_IOERR_FSYNC;
    return real(f)->pMethods->xSync(real(f), flags);
}
int xFileSize(sqlite3_file* f, sqlite3_int64* size) {
    return real(f)->pMethods->xFileSize(real(f), size);
}
int xLock(sqlite3_file* f, int l) {
    return real(f)->pMethods->xLock(real(f), l);
}
int xUnlock(sqlite3_file* f, int l) {
    return real(f)->pMethods->xUnlock(real(f), l);
}
int xCheckReservedLock(sqlite3_file* f, int* out) {
    return real(f)->pMethods->xCheckReservedLock(real(f), out);
}
int xFileControl(sqlite3_file* f, int op, void* arg) {
    return real(f)->pMethods->xFileControl(real(f), op, arg);
}
int xSectorSize(sqlite3_file* f) {
    return real(f)->pMethods->xSectorSize(real(f));
}
int xDeviceCharacteristics(sqlite3_file* f) {
    return real(f)->pMethods->xDeviceCharacteristics(real(f));
}
int xShmMap(sqlite3_file* f, int region, int size, int extend, void volatile** p) {
    return real(f)->pMethods->xShmMap(real(f), region, size, extend, p);
}
int xShmLock(sqlite3_file* f, int offset, int n, int flags) {
    return real(f)->pMethods->xShmLock(real(f), offset, n, flags);
}
void xShmBarrier(sqlite3_file* f) {
    real(f)->pMethods->xShmBarrier(real(f));
}
int xShmUnmap(sqlite3_file* f, int deleteFlag) {
    return real(f)->pMethods->xShmUnmap(real(f), deleteFlag);
}

// Version 2: WAL needs the shared-memory methods; no memory-mapped I/O (xFetch) is offered, so
// every page of the main file goes through xRead/xWrite.
const sqlite3_io_methods kMethods = {2,
                                     xClose,
                                     xRead,
                                     xWrite,
                                     xTruncate,
                                     xSync,
                                     xFileSize,
                                     xLock,
                                     xUnlock,
                                     xCheckReservedLock,
                                     xFileControl,
                                     xSectorSize,
                                     xDeviceCharacteristics,
                                     xShmMap,
                                     xShmLock,
                                     xShmBarrier,
                                     xShmUnmap,
                                     nullptr,
                                     nullptr};

int xOpen(sqlite3_vfs*, sqlite3_filename name, sqlite3_file* f, int flags, int* outFlags) {
    auto* ff = reinterpret_cast<FaultFile*>(f);
    ff->real = reinterpret_cast<sqlite3_file*>(ff + 1);
    std::memset(ff->real, 0, static_cast<std::size_t>(gReal->szOsFile));
    ff->mainDb = (flags & SQLITE_OPEN_MAIN_DB) != 0;
    const int rc = gReal->xOpen(gReal, name, ff->real, flags, outFlags);
    f->pMethods = ff->real->pMethods ? &kMethods : nullptr;
    return rc;
}
int xDelete(sqlite3_vfs*, const char* name, int syncDir) {
    return gReal->xDelete(gReal, name, syncDir);
}
int xAccess(sqlite3_vfs*, const char* name, int flags, int* out) {
    return gReal->xAccess(gReal, name, flags, out);
}
int xFullPathname(sqlite3_vfs*, const char* name, int n, char* out) {
    return gReal->xFullPathname(gReal, name, n, out);
}
int xRandomness(sqlite3_vfs*, int n, char* out) {
    return gReal->xRandomness(gReal, n, out);
}
int xSleep(sqlite3_vfs*, int us) {
    return gReal->xSleep(gReal, us);
}
int xCurrentTime(sqlite3_vfs*, double* t) {
    return gReal->xCurrentTime(gReal, t);
}
int xCurrentTimeInt64(sqlite3_vfs*, sqlite3_int64* t) {
    return gReal->xCurrentTimeInt64(gReal, t);
}
int xGetLastError(sqlite3_vfs*, int n, char* out) {
    return gReal->xGetLastError(gReal, n, out);
}

/// Installs the fault VFS as SQLite's default for the scope (every connection opened inside).
class FaultVfs {
  public:
    FaultVfs() {
        gReal = sqlite3_vfs_find(nullptr);
        vfs_ = *gReal;
        vfs_.iVersion = 2;
        vfs_.szOsFile = static_cast<int>(sizeof(FaultFile)) + gReal->szOsFile;
        vfs_.zName = "underfoot-checkpoint-fault";
        vfs_.pNext = nullptr;
        vfs_.xOpen = xOpen;
        vfs_.xDelete = xDelete;
        vfs_.xAccess = xAccess;
        vfs_.xFullPathname = xFullPathname;
        vfs_.xDlOpen = nullptr;
        vfs_.xDlError = nullptr;
        vfs_.xDlSym = nullptr;
        vfs_.xDlClose = nullptr;
        vfs_.xRandomness = xRandomness;
        vfs_.xSleep = xSleep;
        vfs_.xCurrentTime = xCurrentTime;
        vfs_.xGetLastError = xGetLastError;
        vfs_.xCurrentTimeInt64 = xCurrentTimeInt64;
        ok_ = sqlite3_vfs_register(&vfs_, 1) == SQLITE_OK;
    }
    ~FaultVfs() {
        gFailMainFile = false;
        if (ok_) sqlite3_vfs_unregister(&vfs_);
    }
    FaultVfs(const FaultVfs&) = delete;
    FaultVfs& operator=(const FaultVfs&) = delete;
    bool ok() const { return ok_; }

  private:
    sqlite3_vfs vfs_{};
    bool ok_ = false;
};

class NullPlayer : public StimulusPlayer {
  public:
    StimulusStart start(const Stimulus&, std::uint64_t seed) override { return {seed, ""}; }
    void stop() override {}
};

TrialAnswer answerOf(int realism) {
    TrialAnswer a;
    a.answer = "wood"; // one of the question's options, whatever the stimulus
    a.ratings = {{"realism", realism}};
    return a;
}

} // namespace

TEST(StoreFaults, AnAnswerWhoseCheckpointFailsIsSavedAndTheSessionMovesOn) {
    FaultVfs vfs;
    ASSERT_TRUE(vfs.ok());
    TempDir dir;
    const std::string path = dir.file("checkpoint.db");
    StudyStore store =
        StudyStore::create(path, parseProtocol(miniProtocol(), "mini.toml"), {"CP", "lab", 1, "t"});
    store.registerParticipant({"P1", {}, "", "", "", {}, ""});
    NullPlayer player;
    double now = 10.0;
    Session session(store, "P1", player, {"E", "", "", "t"}, [&] { return now; });
    session.finishBriefing();
    while (session.phase() != SessionPhase::Trial) session.finishBreak();

    // A first answer goes through normally.
    session.play();
    const int first = session.current().index;
    session.answer(answerOf(3));

    // The next answer is committed, then the checkpoint's writes to the study file fail.
    session.play();
    const TrialRecord faulty = session.current();
    gFailMainFile = true;
    std::string message;
    try {
        session.answer(answerOf(6));
    } catch (const AnswerSavedButNotCopied& e) {
        message = e.what();
    }
    gFailMainFile = false;
    ASSERT_FALSE(message.empty()) << "no AnswerSavedButNotCopied while the study file failed";
    EXPECT_GT(gRefusedWrites.load(), 0);
    EXPECT_NE(message.find("IS saved"), std::string::npos) << message;
    EXPECT_NE(message.find(path + "-wal"), std::string::npos) << message;
    EXPECT_NE(message.find(std::to_string(faulty.index + 1)), std::string::npos) << message;

    // The session moved on: the faulty trial is answered and no longer current.
    EXPECT_NE(session.current().index, faulty.index);
    for (const auto& t : store.trials("P1")) {
        if (t.index == faulty.index) {
            EXPECT_TRUE(t.answered);
        }
    }

    // Stored once, as typed, with no "answer_changed" event; a fresh reader sees both answers.
    {
        StudyStore again = StudyStore::open(path);
        int answered = 0;
        for (const auto& t : again.trials("P1")) {
            if (!t.answered) continue;
            ++answered;
            if (t.index == faulty.index) {
                EXPECT_EQ(t.answer.ratings.at("realism"), 6);
            } else {
                EXPECT_EQ(t.index, first);
                EXPECT_EQ(t.answer.ratings.at("realism"), 3);
            }
        }
        EXPECT_EQ(answered, 2);
        for (const auto& e : again.events()) EXPECT_NE(e.kind, "answer_changed") << e.detail;
    }
}
