// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Shared helpers of the experiment tests.
#include "experiment/Protocol.h"

#include <atomic>
#include <filesystem>
#include <string>
#include <unistd.h>

namespace underfoot::experiment::test {

/// A fresh temporary folder, removed at the end of the test.
class TempDir {
  public:
    TempDir() {
        static std::atomic<int> counter{0};
        path_ = std::filesystem::temp_directory_path() /
                ("underfoot-exp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    std::string file(const std::string& name) const { return (path_ / name).string(); }

  private:
    std::filesystem::path path_;
};

inline std::string shipped(const std::string& name) {
    return shippedProtocolDir() + "/" + name;
}
inline std::string dataFile(const std::string& name) {
    return std::string(UNDERFOOT_EXPERIMENT_DATA) + "/" + name;
}

/// A small valid protocol text, with the given extra lines appended.
inline std::string miniProtocol(const std::string& extra = "",
                                const std::string& ordering = "repetitions = 2\n"
                                                              "no_immediate_repeat = true\n") {
    return "[protocol]\nid = \"mini\"\nversion = 1\ntitle = \"Mini\"\n"
           "[design]\ntype = \"within\"\n"
           "[[stimuli]]\nid = \"WD\"\nsurface = \"wood\"\n"
           "[[stimuli]]\nid = \"GL\"\nsurface = \"gravel\"\n"
           "[[stimuli]]\nid = \"WR\"\nsurface = \"wood_reverb\"\nreverb = \"hall\"\n"
           "[ordering]\n" +
           ordering +
           "[questions]\ncomment = true\n[questions.surface]\n"
           "options = [\"wood\", \"gravel\", \"metal\"]\n"
           "[[questions.scales]]\nid = \"realism\"\nprompt = \"Realism\"\nmin = 1\nmax = 7\n" +
           extra;
}

} // namespace underfoot::experiment::test
