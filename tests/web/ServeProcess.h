// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// `underfoot serve` as a child process of a web test (UNDERFOOT_CLI is the program's path;
// UNDERFOOT_WEB_SERVE_PROGRAM in the environment runs another build instead, to compare
// servers): started on a port with extra options, killed (SIGKILL) or stopped (SIGTERM), its
// resident memory read from /proc.
#include "WebTestSupport.h"

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <utility>
#include <vector>

namespace underfoot::web::test {

class ServeProcess {
  public:
    ServeProcess(const StudyFixture& f, int port, const std::vector<std::string>& extra = {}) {
        int fds[2];
        if (::pipe(fds) != 0) throw std::runtime_error("pipe");
        // Everything exec needs is built before fork (the test has threads).
        const char* other = std::getenv("UNDERFOOT_WEB_SERVE_PROGRAM");
        const std::string program = other && *other ? other : UNDERFOOT_CLI;
        std::vector<std::string> args{program,   "serve", "--study", f.study,
                                      "--clips", f.clips, "--port",  std::to_string(port)};
        args.insert(args.end(), kServeTestArgs.begin(), kServeTestArgs.end());
        args.insert(args.end(), extra.begin(), extra.end());
        std::vector<char*> argv;
        for (auto& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        pid_ = ::fork();
        if (pid_ == 0) {
            ::prctl(PR_SET_PDEATHSIG, SIGKILL); // no orphan server if the test is killed
            ::dup2(fds[1], 1);
            ::close(fds[0]);
            ::close(fds[1]);
            ::execv(argv[0], argv.data());
            ::_exit(127);
        }
        ::close(fds[1]);
        out_ = ::fdopen(fds[0], "r");
        char line[1024];
        // "underfoot serve: study ... listening on http://127.0.0.1:PORT/ ..."
        const std::string marker = "listening on http://127.0.0.1:";
        while (std::fgets(line, sizeof line, out_)) {
            const std::string l = line;
            const auto at = l.find(marker);
            if (at == std::string::npos) continue;
            port_ = std::stoi(l.substr(at + marker.size()));
            break;
        }
        if (port_ <= 0) throw std::runtime_error("underfoot serve did not print where it listens");
    }
    ~ServeProcess() {
        if (pid_ > 0) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, nullptr, 0);
        }
        if (out_) std::fclose(out_);
    }
    ServeProcess(const ServeProcess&) = delete;
    ServeProcess& operator=(const ServeProcess&) = delete;

    int port() const { return port_; }
    pid_t pid() const { return pid_; }
    void kill9() {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, nullptr, 0);
        pid_ = -1;
    }
    /// SIGTERM; returns the exit status and the rest of the output.
    std::pair<int, std::string> terminate() {
        ::kill(pid_, SIGTERM);
        std::string rest;
        char line[1024];
        while (std::fgets(line, sizeof line, out_)) rest += line;
        int status = 0;
        ::waitpid(pid_, &status, 0);
        pid_ = -1;
        return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, rest};
    }
    /// Resident memory of the server (kB, VmRSS of /proc/PID/status).
    long rssKb() const {
        std::FILE* f = std::fopen(("/proc/" + std::to_string(pid_) + "/status").c_str(), "r");
        if (!f) return -1;
        char line[256];
        long kb = -1;
        while (std::fgets(line, sizeof line, f))
            if (std::sscanf(line, "VmRSS: %ld kB", &kb) == 1) break;
        std::fclose(f);
        return kb;
    }

  private:
    pid_t pid_ = -1;
    std::FILE* out_ = nullptr;
    int port_ = -1;
};

} // namespace underfoot::web::test
