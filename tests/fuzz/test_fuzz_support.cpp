// SPDX-License-Identifier: GPL-3.0-or-later
// Regression test of the harness helpers (FuzzSupport.h), not a fuzz target. A CI run's
// fuzz_web_request stopped with "cannot copy the template study: Interrupted system call":
// libFuzzer's -timeout watchdog raises SIGALRM with a handler installed without SA_RESTART, and
// std::filesystem::copy_file (sendfile) fails when the signal lands during the copy. Here a
// SIGALRM every 50 µs, with the same kind of handler, lands during many copies of a 4 MiB
// file: fuzz::copyFile must copy every byte every time. How often std::filesystem::copy_file
// fails under the same signals is printed, to show that the storm does interrupt copies here.
#include "FuzzSupport.h"

#include <algorithm>
#include <csignal>
#include <cstring>
#include <iostream>

#include <sys/time.h>

namespace {

void onAlarm(int) {}

std::string readAll(const std::string& path) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    std::string bytes(static_cast<std::size_t>(std::max<std::streamoff>(0, in.tellg())), '\0');
    in.seekg(0);
    in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return bytes;
}

} // namespace

int main() {
    namespace fs = std::filesystem;
    using namespace underfoot;
    const std::string from = (fuzz::scratchDir() / "source.bin").string();
    const std::string to = (fuzz::scratchDir() / "copy.bin").string();
    std::string bytes(4u << 20, '\0');
    for (std::size_t i = 0; i < bytes.size(); ++i)
        bytes[i] = static_cast<char>((i * 2654435761u) >> 13);
    {
        std::ofstream out(from, std::ios::binary);
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    }

    struct sigaction sa;
    std::memset(&sa, 0, sizeof sa);
    sa.sa_handler = onAlarm;
    sa.sa_flags = 0; // as libFuzzer installs its SIGALRM handler: no SA_RESTART
    sigaction(SIGALRM, &sa, nullptr);
    const itimerval storm{{0, 50}, {0, 50}};
    setitimer(ITIMER_REAL, &storm, nullptr);

    constexpr int kCopies = 30;
    int interrupted = 0;
    for (int i = 0; i < kCopies; ++i) {
        std::error_code ec;
        fs::remove(to, ec);
        fs::copy_file(from, to, ec);
        if (ec) ++interrupted;
    }
    for (int i = 0; i < kCopies; ++i) {
        fuzz::copyFile(from, to);
        if (readAll(to) != bytes) fuzz::fail("copy " + std::to_string(i) + " differs");
    }
    fuzz::copyFile(from, from + ".again"); // onto a new file too
    const itimerval off{};
    setitimer(ITIMER_REAL, &off, nullptr);
    if (readAll(from + ".again") != bytes) fuzz::fail("the copy onto a new file differs");
    std::cout << "fuzz::copyFile: " << kCopies + 1 << " copies of 4 MiB under SIGALRM every "
              << "50 us, all equal; std::filesystem::copy_file failed " << interrupted << " of "
              << kCopies << " times under the same signals\n";
    return 0;
}
