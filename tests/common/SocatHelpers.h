// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Test helpers: a socat pseudo-terminal pair as a child process, a raw writer emulating the
// shoes at 1 kHz (ShoeLineWriter: a ShoeScript's lines from a thread of its own), and a recorder
// of a source's state transitions.
#include "engine/dsp/Random.h"
#include "engine/io/sensors/SensorClock.h"
#include "engine/io/sensors/SensorStatus.h"
#include "engine/io/sensors/ShoeProtocol.h"
#include "engine/io/sensors/ShoeSimulator.h"
#include "tests/common/ScratchDir.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fcntl.h>
#include <filesystem>
#include <functional>
#include <mutex>
#include <spawn.h>
#include <string>
#include <sys/wait.h>
#include <termios.h>
#include <thread>
#include <unistd.h>
#include <utility>
#include <vector>

extern char** environ;

namespace underfoot::test {

using namespace underfoot::engine;
namespace fs = std::filesystem;

inline bool socatInstalled() {
    const char* path = std::getenv("PATH");
    std::string p = path ? path : "/usr/bin:/bin";
    std::size_t start = 0;
    while (start <= p.size()) {
        const std::size_t end = std::min(p.find(':', start), p.size());
        if (::access((p.substr(start, end - start) + "/socat").c_str(), X_OK) == 0) return true;
        start = end + 1;
    }
    return false;
}

/// `socat -d -d pty,raw,echo=0,link=DIR/shoes pty,raw,echo=0,link=DIR/app` as a child process.
class SocatPair {
  public:
    explicit SocatPair(const std::string& name) {
        const fs::path dir = underfoot::test::scratchDir("socat");
        shoes = (dir / (name + "_shoes")).string();
        app = (dir / (name + "_app")).string();
        const std::string log = (dir / (name + "_socat.log")).string();
        const std::string a1 = "pty,raw,echo=0,link=" + shoes;
        const std::string a2 = "pty,raw,echo=0,link=" + app;
        const char* argv[] = {"socat", "-d", "-d", a1.c_str(), a2.c_str(), nullptr};
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                         0644);
        const int rc = posix_spawnp(&pid_, "socat", &actions, nullptr,
                                    const_cast<char* const*>(argv), environ);
        posix_spawn_file_actions_destroy(&actions);
        if (rc != 0) {
            pid_ = -1;
            return;
        }
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
        while (std::chrono::steady_clock::now() < deadline &&
               !(fs::exists(shoes) && fs::exists(app)))
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ~SocatPair() { kill(); }
    bool ready() const { return pid_ > 0 && fs::exists(shoes) && fs::exists(app); }
    /// Ends socat (the "unplug"); returns the sensor-clock time of the kill.
    double kill() {
        if (pid_ <= 0) return 0;
        const double t = sensorClockSeconds();
        ::kill(pid_, SIGTERM);
        int status = 0;
        ::waitpid(pid_, &status, 0);
        pid_ = -1;
        return t;
    }
    std::string shoes, app;

  private:
    pid_t pid_ = -1;
};

/// Opens the "shoes" end for writing, raw.
inline int openWriter(const std::string& path) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) return fd;
    termios t{};
    if (::tcgetattr(fd, &t) == 0) {
        ::cfmakeraw(&t);
        ::tcsetattr(fd, TCSANOW, &t);
    }
    return fd;
}

inline bool writeAll(int fd, const std::string& s) {
    std::size_t done = 0;
    while (done < s.size()) {
        const ssize_t n = ::write(fd, s.data() + done, s.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        done += static_cast<std::size_t>(n);
    }
    return true;
}

/// Writes producer(tick) at 1 kHz (tick n at start + n ms); records each tick's write time.
/// Stops early when a write fails (the pty went away) or `stop` is set.
inline void paced(int fd, std::size_t ticks,
                  const std::function<std::string(std::size_t)>& producer,
                  std::vector<double>* times = nullptr, const std::atomic<bool>* stop = nullptr) {
    if (times) times->assign(ticks, 0.0);
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < ticks; ++i) {
        if (stop && stop->load()) return;
        std::this_thread::sleep_until(start + std::chrono::milliseconds(i));
        const std::string s = producer(i);
        if (!s.empty() && !writeAll(fd, s)) return;
        if (times) (*times)[i] = sensorClockSeconds();
    }
}

/// Writes a ShoeScript's header and lines at 1 kHz (line i at start + i ms, its sensor noise
/// seeded with 3) into `fd` from a thread of its own, until destroyed or a write fails. The
/// script must outlive the writer.
class ShoeLineWriter {
  public:
    ShoeLineWriter(int fd, const ShoeScript& script)
        : thread_([this, fd, &script] {
              writeAll(fd, shoeHeaderLine());
              Random noise(3);
              const auto start = std::chrono::steady_clock::now();
              for (std::size_t i = 0; !stop_.load(); ++i) {
                  std::this_thread::sleep_until(start + std::chrono::milliseconds(i));
                  if (!writeAll(fd, formatShoeLine(static_cast<std::uint32_t>(i),
                                                   script.sample(i, noise))))
                      break;
              }
          }) {}
    ~ShoeLineWriter() {
        stop_ = true;
        thread_.join();
    }
    ShoeLineWriter(const ShoeLineWriter&) = delete;
    ShoeLineWriter& operator=(const ShoeLineWriter&) = delete;

  private:
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

/// State transitions seen by the status callback, with their times.
struct Transitions {
    std::mutex mutex;
    std::vector<std::pair<SensorState, double>> seen;
    std::vector<std::string> messages;
    void operator()(const SensorStatus& s) {
        std::lock_guard lock(mutex);
        seen.emplace_back(s.state, s.stateSinceS);
        messages.push_back(s.message);
    }
    /// Time of the first transition into `state` at or after `afterS` (0 = never).
    double first(SensorState state, double afterS = 0) {
        std::lock_guard lock(mutex);
        for (const auto& [st, t] : seen)
            if (st == state && t >= afterS) return t;
        return 0;
    }
    /// Message of the first transition into `state` ("" = never).
    std::string messageOf(SensorState state) {
        std::lock_guard lock(mutex);
        for (std::size_t i = 0; i < seen.size(); ++i)
            if (seen[i].first == state) return messages[i];
        return {};
    }
};

} // namespace underfoot::test
