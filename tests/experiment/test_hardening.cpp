// SPDX-License-Identifier: GPL-3.0-or-later
// A damaged study file is refused with its name and what is wrong, never indexed or run.
#include "TestSupport.h"
#include "experiment/Store.h"

#include <SQLiteCpp/SQLiteCpp.h>
#include <gtest/gtest.h>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

namespace {
std::string openError(const std::string& path) {
    try {
        (void)StudyStore::open(path);
    } catch (const StoreError& e) {
        return e.what();
    }
    return "";
}

void setUserVersion(const std::string& path, long long v) {
    SQLite::Database db(path, SQLite::OPEN_READWRITE);
    db.exec("PRAGMA user_version = " + std::to_string(v));
}
} // namespace

TEST(StoreHardening, UnknownSchemaVersionsAreRefusedWithTheFileName) {
    TempDir dir;
    const std::string path = dir.file("damaged.db");
    {
        StudyStore::create(path, loadProtocol(shipped("tvcg2011_exp1.toml")),
                           {"D1", "lab", 1, "test"});
    }
    for (long long v : {-1LL, -2147483648LL, 0LL, 99LL, 2147483647LL}) {
        setUserVersion(path, v);
        const std::string msg = openError(path);
        ASSERT_FALSE(msg.empty()) << "user_version " << v << " was accepted";
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_NE(msg.find("schema version " + std::to_string(v)), std::string::npos) << msg;
    }
    // Back to ours: the study opens again (the refusal wrote nothing).
    setUserVersion(path, kSchemaVersion);
    EXPECT_EQ(openError(path), "");
}

// ---- Store faults: each counts the acknowledged answers before and after. ----------

#include <fmt/format.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <sstream>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>

namespace {

Protocol miniStudyProtocol() {
    return parseProtocol(miniProtocol(), "mini.toml");
}

TrialAnswer validAnswer(int i) {
    TrialAnswer a;
    a.answer = (i % 2) ? "wood" : "gravel";
    a.ratings = {{"realism", 1 + i % 7}};
    return a;
}

/// Starts and answers the next `n` trials of `code` in session `session`; returns how many
/// commitAnswer calls returned (acknowledged).
int answerNext(StudyStore& s, const std::string& code, int session, int n) {
    int acked = 0;
    for (int k = 0; k < n; ++k) {
        const auto next = s.firstUnanswered(code);
        if (!next) break;
        s.markTrialStarted(code, *next, session, 100 + static_cast<std::uint64_t>(*next),
                           std::nullopt);
        s.commitAnswer(code, *next, validAnswer(*next), 1.0);
        ++acked;
    }
    return acked;
}

/// Answered trials of `code` as "index:answer:realism" in trial order (what was typed).
std::vector<std::string> answersOf(const StudyStore& s, const std::string& code) {
    std::vector<std::string> out;
    for (const auto& t : s.trials(code))
        if (t.answered)
            out.push_back(fmt::format(
                "{}:{}:{}", t.index, t.answer.answer,
                t.answer.ratings.count("realism") ? t.answer.ratings.at("realism") : -1));
    return out;
}

std::vector<std::string> expectedAnswers(int n) {
    std::vector<std::string> out;
    for (int i = 0; i < n; ++i)
        out.push_back(fmt::format("{}:{}:{}", i, validAnswer(i).answer, 1 + i % 7));
    return out;
}

std::string readAll(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// Runs `body` in a child process; returns its exit status (or 128 + signal).
template <typename Body>
int inChild(Body&& body) {
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
        int code = 99;
        try {
            code = body();
        } catch (const std::exception& e) {
            std::fprintf(stderr, "child: %s\n", e.what());
            code = 98;
        }
        std::fflush(nullptr);
        ::_exit(code);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

} // namespace

TEST(StoreFaults, TwoSessionsOnOneParticipantAreRefusedWithHolderAndSince) {
    TempDir dir;
    const std::string path = dir.file("two.db");
    {
        StudyStore s = StudyStore::create(path, miniStudyProtocol(), {"T", "lab", 1, "t"});
        s.registerParticipant({"P1", {}, "", "", "", {}, ""});
    }
    // A child process holds P1's session and answers 2 trials, then waits (a pipe) while the
    // parent tries a second session; then it tries to answer once more.
    int toChild[2], toParent[2];
    ASSERT_EQ(::pipe(toChild), 0);
    ASSERT_EQ(::pipe(toParent), 0);
    std::fflush(nullptr);
    const pid_t child = ::fork();
    if (child == 0) {
        int code = 0;
        try {
            StudyStore s = StudyStore::open(path);
            const int session = s.startSession("P1", {"anna", "", "", "t"});
            char c = static_cast<char>('0' + answerNext(s, "P1", session, 2));
            (void)!::write(toParent[1], &c, 1);
            (void)!::read(toChild[0], &c, 1); // the parent took the session over
            try {
                answerNext(s, "P1", session, 1);
                code = 10; // wrongly accepted
            } catch (const StoreError& e) {
                code = std::string(e.what()).find("taken over") != std::string::npos ? 0 : 11;
            }
        } catch (const std::exception& e) {
            std::fprintf(stderr, "child: %s\n", e.what());
            code = 12;
        }
        ::_exit(code);
    }
    // Whatever fails below, the child never outlives the test (it would wait on its pipe forever).
    struct ChildGuard {
        pid_t pid;
        bool reaped = false;
        ~ChildGuard() {
            if (!reaped) {
                ::kill(pid, SIGKILL);
                ::waitpid(pid, nullptr, 0);
            }
        }
    } guard{child};
    char acked = 0;
    ASSERT_EQ(::read(toParent[0], &acked, 1), 1);
    ASSERT_EQ(acked, '2');
    StudyStore s = StudyStore::open(path);
    const auto before = answersOf(s, "P1");
    EXPECT_EQ(before, expectedAnswers(2));
    try {
        s.startSession("P1", {"ben", "", "", "t"});
        FAIL() << "a second live session on P1 was accepted";
    } catch (const StoreError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_NE(msg.find(fmt::format("held by process {}", child)), std::string::npos) << msg;
        EXPECT_NE(msg.find("experimenter 'anna'"), std::string::npos) << msg;
        EXPECT_NE(msg.find(" since 20"), std::string::npos) << msg;
        EXPECT_NE(msg.find("--take-over"), std::string::npos) << msg;
    }
    // Nothing was written by the refusal; the documented take-over works and is journaled.
    EXPECT_EQ(answersOf(s, "P1"), before);
    SessionSettings takeOver{"ben", "", "", "t"};
    takeOver.takeOver = true;
    const int session = s.startSession("P1", takeOver);
    bool journaled = false;
    for (const auto& e : s.events()) journaled = journaled || e.kind == "lease_taken_over";
    EXPECT_TRUE(journaled);
    char go = 'g';
    ASSERT_EQ(::write(toChild[1], &go, 1), 1);
    int status = 0;
    ::waitpid(child, &status, 0);
    guard.reaped = true;
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << "the old session wrote after the take-over";
    // The old session's answers are kept as they were typed; the new session goes on.
    EXPECT_EQ(answersOf(s, "P1"), before);
    EXPECT_EQ(answerNext(s, "P1", session, 1), 1);
    EXPECT_EQ(answersOf(s, "P1"), expectedAnswers(3));
}

TEST(StoreFaults, ACrashedSessionsLeaseIsRecovered) {
    TempDir dir;
    const std::string path = dir.file("crash.db");
    {
        StudyStore s = StudyStore::create(path, miniStudyProtocol(), {"T", "lab", 1, "t"});
        s.registerParticipant({"P1", {}, "", "", "", {}, ""});
    }
    // The child answers 3 trials and dies by SIGKILL holding the lease.
    const int status = inChild([&] {
        StudyStore s = StudyStore::open(path);
        answerNext(s, "P1", s.startSession("P1", {}), 3);
        ::raise(SIGKILL);
        return 0;
    });
    ASSERT_EQ(status, 128 + SIGKILL);
    StudyStore s = StudyStore::open(path);
    const int session = s.startSession("P1", {}); // the dead holder's lease is recovered
    bool recovered = false;
    for (const auto& e : s.events()) recovered = recovered || e.kind == "lease_recovered";
    EXPECT_TRUE(recovered);
    EXPECT_EQ(answersOf(s, "P1"), expectedAnswers(3));
    EXPECT_EQ(answerNext(s, "P1", session, 1), 1);
}

TEST(StoreFaults, DeletedWalAfterAKillLosesNoAcknowledgedAnswer) {
    TempDir dir;
    const std::string path = dir.file("wal.db");
    {
        StudyStore s = StudyStore::create(path, miniStudyProtocol(), {"T", "lab", 1, "t"});
        s.registerParticipant({"P1", {}, "", "", "", {}, ""});
    }
    const int acknowledged = 5;
    const int status = inChild([&] {
        StudyStore s = StudyStore::open(path);
        if (answerNext(s, "P1", s.startSession("P1", {}), acknowledged) != acknowledged) return 1;
        ::raise(SIGKILL); // no clean close: whatever is only in -wal stays there
        return 0;
    });
    ASSERT_EQ(status, 128 + SIGKILL);
    // The lab cleans "temporary files".
    std::filesystem::remove(path + "-wal");
    std::filesystem::remove(path + "-shm");
    StudyStore s = StudyStore::open(path);
    EXPECT_EQ(answersOf(s, "P1"), expectedAnswers(acknowledged));
}

TEST(StoreFaults, ACorruptedPageIsRefusedWithHowToRecoverAndNothingIsWritten) {
    TempDir dir;
    const std::string path = dir.file("corrupt.db");
    {
        StudyStore s = StudyStore::create(path, miniStudyProtocol(), {"T", "lab", 1, "t"});
        s.registerParticipant({"P1", {}, "", "", "", {}, ""});
        EXPECT_EQ(answerNext(s, "P1", s.startSession("P1", {}), 4), 4);
    }
    std::string bytes = readAll(path);
    ASSERT_GT(bytes.size(), 4u * 4096u);
    // Damage the b-tree pages 2 to 4 (page 1 holds the header and the schema).
    for (std::size_t i = 4096 + 8; i < 4u * 4096u; i += 7) bytes[i] = static_cast<char>(i * 31);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    try {
        (void)StudyStore::open(path);
        FAIL() << "a damaged study was opened";
    } catch (const StoreError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_NE(msg.find("damaged"), std::string::npos) << msg;
        EXPECT_NE(msg.find(".recover"), std::string::npos) << msg;
        EXPECT_NE(msg.find(".backup"), std::string::npos) << msg;
    }
    EXPECT_EQ(readAll(path), bytes) << "the damaged file was written to";
}

TEST(StoreFaults, DiskFullNamesFileAndCauseLosesNothingAndResumes) {
    TempDir dir;
    const std::string mountPoint = dir.file("small_disk");
    std::filesystem::create_directories(mountPoint);
    if (::mount("tmpfs", mountPoint.c_str(), "tmpfs", 0, "size=1m") != 0)
        GTEST_SKIP() << "cannot mount a small tmpfs here (" << std::strerror(errno)
                     << "); disk full not tested";
    struct Unmount {
        std::string p;
        ~Unmount() { ::umount2(p.c_str(), MNT_DETACH); }
    } unmount{mountPoint};
    const std::string path = mountPoint + "/full.db";
    StudyStore s = StudyStore::create(path, miniStudyProtocol(), {"T", "lab", 1, "t"});
    s.registerParticipant({"P1", {}, "", "", "", {}, ""});
    const int session = s.startSession("P1", {});
    int acked = answerNext(s, "P1", session, 2);
    // Fill the disk.
    {
        std::ofstream filler(mountPoint + "/filler", std::ios::binary);
        const std::string block(4096, 'x');
        while (filler.write(block.data(), block.size())) {
        }
    }
    // Answers with long comments: the file must grow (small answers reuse freed pages).
    std::string message;
    try {
        for (int k = 0; k < 4; ++k) {
            const auto next = s.firstUnanswered("P1");
            ASSERT_TRUE(next);
            s.markTrialStarted("P1", *next, session, 7, std::nullopt);
            TrialAnswer a = validAnswer(*next);
            a.comment = std::string(300000, static_cast<char>('a' + k));
            s.commitAnswer("P1", *next, a, 1.0);
            ++acked;
        }
    } catch (const StoreError& e) {
        message = e.what();
    }
    ASSERT_FALSE(message.empty()) << "no write failed on a full disk";
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find("disk is full"), std::string::npos) << message;
    // Space again: every acknowledged answer is there, as typed, and the session goes on.
    std::filesystem::remove(mountPoint + "/filler");
    {
        StudyStore again = StudyStore::open(path);
        const auto stored = answersOf(again, "P1");
        ASSERT_GE(static_cast<int>(stored.size()), acked);
        EXPECT_EQ(stored, expectedAnswers(static_cast<int>(stored.size())));
        const int resumed = again.startSession("P1", {}); // same process: lease recovered
        EXPECT_EQ(answerNext(again, "P1", resumed, 1), 1);
    }
}

TEST(StoreFaults, ReadOnlyFileAndFolderNameTheFileAndTheCause) {
    TempDir dir;
    const std::string folder = dir.file("ro");
    std::filesystem::create_directories(folder);
    const std::string path = folder + "/ro.db";
    {
        StudyStore s = StudyStore::create(path, miniStudyProtocol(), {"T", "lab", 1, "t"});
        s.registerParticipant({"P1", {}, "", "", "", {}, ""});
        EXPECT_EQ(answerNext(s, "P1", s.startSession("P1", {}), 2), 2);
    }
    const std::string before = readAll(path);
    for (const bool folderWritable : {false, true}) {
        ::chmod(folder.c_str(), folderWritable ? 0777 : 0755);
        ::chmod(path.c_str(), 0444);
        // In /tmp (sticky, world-writable): the unprivileged child can write its message there.
        const std::string report =
            fmt::format("/tmp/underfoot_ro_report_{}_{}.txt", ::getpid(), folderWritable);
        const int status = inChild([&] {
            // An unprivileged user (root writes anything).
            if (::geteuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) return 20;
            std::string msg;
            try {
                StudyStore s = StudyStore::open(path);
                answerNext(s, "P1", s.startSession("P1", {}), 1);
                return 21; // wrote to a read-only study?
            } catch (const StoreError& e) {
                msg = e.what();
            }
            std::ofstream(report) << msg;
            return 0;
        });
        if (status == 20) GTEST_SKIP() << "cannot drop privileges to test a read-only study";
        ASSERT_EQ(status, 0) << "folder writable: " << folderWritable;
        const std::string msg = readAll(report);
        std::filesystem::remove(report);
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_NE(msg.find("read-only"), std::string::npos) << msg;
        EXPECT_EQ(readAll(path), before);
    }
    ::chmod(folder.c_str(), 0755);
    ::chmod(path.c_str(), 0644);
    StudyStore s = StudyStore::open(path);
    EXPECT_EQ(answersOf(s, "P1"), expectedAnswers(2));
}

// ---- Read-only open mode: an archived study still exports and analyzes. ---------

#include "experiment/Export.h"

TEST(StoreFaults, ReadOnlyArchivedStudyExportsWithoutWritingAndRefusesASession) {
    TempDir dir;
    const std::string folder = dir.file("archive");
    std::filesystem::create_directories(folder);
    const std::string path = folder + "/archived.db";
    {
        StudyStore s = StudyStore::create(path, miniStudyProtocol(), {"A", "lab", 1, "t"});
        s.registerParticipant({"P1", {}, "", "", "", {}, ""});
        const int session = s.startSession("P1", {});
        EXPECT_EQ(answerNext(s, "P1", session, 3), 3);
        s.endSession("P1", session, false);
    }
    std::error_code ec;
    std::filesystem::remove(path + "-wal", ec); // closed cleanly: nothing waits in the -wal
    std::filesystem::remove(path + "-shm", ec);
    const std::string before = readAll(path);
    // file mode, folder mode: read-only file in a read-only folder, read-only file in a
    // writable folder, writable file in a read-only folder.
    for (const auto& [fileMode, folderMode] :
         {std::pair{0444, 0555}, std::pair{0444, 0777}, std::pair{0666, 0555}}) {
        ::chmod(path.c_str(), static_cast<mode_t>(fileMode));
        ::chmod(folder.c_str(), static_cast<mode_t>(folderMode));
        const std::string report = fmt::format("/tmp/underfoot_ro_open_{}_{:o}_{:o}.txt",
                                               ::getpid(), fileMode, folderMode);
        const int status = inChild([&] {
            if (::geteuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) return 20;
            std::ofstream out(report);
            StudyStore s = StudyStore::openReadOnly(path);
            out << "readOnly " << s.readOnly() << "\n";
            for (const auto& a : answersOf(s, "P1")) out << "answer " << a << "\n";
            out << "participants " << s.participants().size() << "\n";
            out << "info " << s.info().code << "\n";
            std::ostringstream trials, participants;
            out << "trialRows " << writeTrialsCsv(s, trials, ExportScope::Answered) << "\n";
            out << "participantRows " << writeParticipantsCsv(s, participants) << "\n";
            try {
                (void)s.startSession("P1", {});
                out << "session started\n";
            } catch (const StoreError& e) {
                out << "session refused: " << e.what() << "\n";
            }
            // The reading commands' open (export, analyze, study info/participants).
            StudyStore r = StudyStore::openForReading(path);
            out << "forReading " << answersOf(r, "P1").size() << "\n";
            return 0;
        });
        if (status == 20) GTEST_SKIP() << "cannot drop privileges to test a read-only study";
        ::chmod(folder.c_str(), 0755);
        const std::string got = readAll(report);
        std::filesystem::remove(report);
        const std::string where = fmt::format("file {:o} folder {:o}: ", fileMode, folderMode);
        ASSERT_EQ(status, 0) << where << got;
        std::string expected = "readOnly 1\n";
        for (const auto& a : expectedAnswers(3)) expected += "answer " + a + "\n";
        expected += "participants 1\ninfo A\ntrialRows 3\nparticipantRows 1\n";
        EXPECT_EQ(got.substr(0, expected.size()), expected) << where << got;
        const std::string refusal =
            "session refused: " + path + ": participant 'P1': a session cannot start";
        EXPECT_NE(got.find(refusal), std::string::npos) << where << got;
        EXPECT_NE(got.find("read-only"), std::string::npos) << where << got;
        EXPECT_NE(got.find("forReading 3\n"), std::string::npos) << where << got;
        EXPECT_EQ(readAll(path), before) << where << "the study file changed";
        if (folderMode == 0555) { // nothing could be created next to it
            EXPECT_FALSE(std::filesystem::exists(path + "-shm")) << where;
        }
    }
    ::chmod(path.c_str(), 0644);
    StudyStore s = StudyStore::open(path);
    EXPECT_EQ(answersOf(s, "P1"), expectedAnswers(3));
}

TEST(StoreFaults, ReadOnlyOpenOfAnOlderSchemaSaysAMigrationIsNeeded) {
    TempDir dir;
    const std::string path = dir.file("old.db");
    { StudyStore::create(path, miniStudyProtocol(), {"O", "lab", 1, "t"}); }
    setUserVersion(path, kSchemaVersion - 1); // as an older Underfoot left it
    const std::string before = readAll(path);
    std::string msg;
    try {
        (void)StudyStore::openReadOnly(path);
    } catch (const StoreError& e) {
        msg = e.what();
    }
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find(fmt::format("schema version {}", kSchemaVersion - 1)), std::string::npos)
        << msg;
    EXPECT_NE(msg.find("migrate"), std::string::npos) << msg;
    EXPECT_EQ(readAll(path), before);
}

TEST(StoreJournal, RatingsAndParticipantFieldsAreJournaledAsNameValueText) {
    // The journal events carry the stored ratings and participant fields as "name=value ...",
    // in name order (the events table is what a damaged study is checked against).
    TempDir dir;
    StudyStore s = StudyStore::create(dir.file("j.db"), miniStudyProtocol(), {"J", "lab", 3, "t"});
    s.registerParticipant({"P1", {}, "", "", "", {}, ""});
    const int session = s.startSession("P1", {});
    ASSERT_EQ(answerNext(s, "P1", session, 1), 1);
    TrialAnswer changed = validAnswer(0);
    changed.ratings = {{"realism", 3}, {"quality", 5}};
    s.commitAnswer("P1", 0, changed, 2.0);
    StudyStore w = StudyStore::create(
        dir.file("w.db"), loadProtocol(shipped("wading_realism.toml")), {"W", "lab", 3, "t"});
    w.registerParticipant({"P1", {}, "", "", "", {}, ""},
                          {{"music_expertise", "none"},
                           {"audio_expertise", "professional"},
                           {"listening_device", "laptop_speakers"}});
    std::vector<std::string> details;
    for (const auto& e : s.events())
        if (e.kind == "answered" || e.kind == "answer_changed") details.push_back(e.detail);
    for (const auto& e : w.events())
        if (e.kind == "participant_registered") details.push_back(e.detail);
    ASSERT_EQ(details.size(), 3u);
    EXPECT_NE(details[0].find("\"ratings\":\"realism=1\""), std::string::npos) << details[0];
    EXPECT_NE(details[1].find("\"ratings\":\"quality=5 realism=3\""), std::string::npos)
        << details[1];
    EXPECT_NE(details[2].find("\"fields\":\"audio_expertise=professional "
                              "listening_device=laptop_speakers music_expertise=none\""),
              std::string::npos)
        << details[2];
}
