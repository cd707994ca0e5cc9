// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A JACK server with the dummy driver (`jackd --no-realtime -d dummy -r 48000 -p PERIOD -C 4
/// -P 6`) under a server name of its own, standing in for the sound card in the live tests.
/// RtAudio's JACK API then sees the device "system" with 4 inputs and 6 outputs. The server is a
/// child that dies with the test program (PR_SET_PDEATHSIG), even when a test crashes.
#include "engine/io/AudioDevice.h"
#include "engine/scene/LiveEngine.h"

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace underfoot::test {

/// The full path of a program found in PATH ("" when absent).
inline std::string findProgram(const std::string& name) {
    const char* path = std::getenv("PATH");
    const std::string p = path ? path : "/usr/bin:/bin";
    std::size_t start = 0;
    while (start <= p.size()) {
        const std::size_t colon = std::min(p.find(':', start), p.size());
        const auto candidate = std::filesystem::path(p.substr(start, colon - start)) / name;
        if (access(candidate.c_str(), X_OK) == 0) return candidate.string();
        start = colon + 1;
    }
    return {};
}

/// Runs a command (argv) to completion; returns its exit status and, in `output`, its stdout
/// and stderr.
inline int runProgram(const std::vector<std::string>& args, std::string* output = nullptr) {
    std::string cmd;
    for (const auto& a : args) cmd += "'" + a + "' ";
    cmd += "2>&1";
    FILE* f = popen(cmd.c_str(), "r");
    if (!f) return -1;
    char buf[512];
    std::string out;
    while (std::fgets(buf, sizeof buf, f)) out += buf;
    const int status = pclose(f);
    if (output) *output = out;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class JackDummyServer {
  public:
    /// Starts the server as `JACK_DEFAULT_SERVER=<prefix>_<pid>` (also set for this process,
    /// with JACK_NO_START_SERVER=1) and waits up to 10 s for the dummy driver's ports. Its
    /// output goes to `logPath`. Nothing happens when jackd is not installed (installed() false).
    /// `synchronous`: `jackd -S` (the server waits for every client to finish each cycle, so
    /// that a client reading another's outputs never sees a half-written or skipped period,
    /// even when the cycle overruns).
    JackDummyServer(const std::string& prefix, const std::filesystem::path& logPath,
                    int period = 64, bool synchronous = false) {
        jackd_ = findProgram("jackd");
        if (jackd_.empty()) return;
        name_ = prefix + "_" + std::to_string(getpid());
        setenv("JACK_DEFAULT_SERVER", name_.c_str(), 1);
        setenv("JACK_NO_START_SERVER", "1", 1);
        std::vector<std::string> args{jackd_, "--no-realtime"};
        if (synchronous) args.push_back("-S");
        for (std::string a : {"-d", "dummy", "-r", "48000", "-p"}) args.push_back(a);
        args.push_back(std::to_string(period));
        for (std::string a : {"-C", "4", "-P", "6"}) args.push_back(a);
        std::vector<char*> argv;
        for (auto& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        const pid_t parent = getpid();
        pid_ = fork();
        if (pid_ == 0) {
            prctl(PR_SET_PDEATHSIG, SIGTERM);
            if (getppid() != parent) _exit(127); // the parent died before prctl
            const int fd = open(logPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
            if (fd >= 0) {
                dup2(fd, 1);
                dup2(fd, 2);
                close(fd);
            }
            execve(jackd_.c_str(), argv.data(), environ);
            _exit(127);
        }
        const std::string lsp = findProgram("jack_lsp");
        for (int i = 0; i < 100 && pid_ > 0; ++i) {
            std::string out;
            if (runProgram({lsp}, &out) == 0 &&
                out.find("system:playback_6") != std::string::npos) {
                ready_ = true;
                break;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
        // The ports exist, but on a loaded machine RtAudio's probe of the new server can still
        // fail for a moment (a client that cannot open leaves the device out of the list: the
        // live engine then says `audio device "system" not found`). Ready means the engine's
        // own device list shows it, within the same 10 s.
        for (int i = 0; i < 100 && ready_; ++i) {
            bool seen = false;
            try {
                for (const auto& d : engine::listAudioDevices("jack"))
                    seen = seen || d.name == "system";
            } catch (const std::exception&) {
            }
            if (seen) break;
            if (i == 99) ready_ = false;
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
    }
    ~JackDummyServer() {
        if (pid_ <= 0) return;
        kill(pid_, SIGTERM);
        int status = 0;
        for (int i = 0; i < 50 && waitpid(pid_, &status, WNOHANG) == 0; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        if (waitpid(pid_, &status, WNOHANG) == 0) {
            kill(pid_, SIGKILL);
            waitpid(pid_, &status, 0);
        }
    }
    JackDummyServer(const JackDummyServer&) = delete;
    JackDummyServer& operator=(const JackDummyServer&) = delete;

    bool installed() const noexcept { return !jackd_.empty(); }
    bool ready() const noexcept { return ready_; }
    const std::string& name() const noexcept { return name_; }

  private:
    std::string jackd_, name_;
    pid_t pid_ = -1;
    bool ready_ = false;
};

/// engine.open(settings) on the dummy server. On a loaded machine RtAudio's probe of the server
/// can fail for a moment even after the server showed its ports and the device: the probe's
/// own client cannot open and the device list comes back empty. open() then says `audio device
/// "system" not found`, or, when it is openStream's own second probe that fails twice, that the
/// device "refused" the stream because its "device parameter value is invalid". The server is
/// up, so either is retried for up to 5 s; any other error is thrown at once.
inline void openJackDevice(engine::LiveEngine& engine, const engine::AudioSettings& settings) {
    for (int i = 0;; ++i) {
        try {
            engine.open(settings);
            return;
        } catch (const std::exception& e) {
            const std::string what = e.what();
            const bool transient =
                what.find("\"" + settings.device + "\" not found") != std::string::npos ||
                what.find("device parameter value is invalid") != std::string::npos;
            if (!transient || i == 49) throw;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
}

} // namespace underfoot::test
