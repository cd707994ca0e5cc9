// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Helpers of the libFuzzer targets (tests/fuzz/README.md). A target feeds one input to one
/// reader of outside input. The reader may refuse it only with its documented error type, whose
/// message must name the input (file or source name); any other exception, a crash, a sanitizer
/// report, a hang or an unbounded allocation is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <typeinfo>

#include <unistd.h>

namespace underfoot::fuzz {

inline std::string text(const std::uint8_t* data, std::size_t size) {
    return std::string(reinterpret_cast<const char*>(data), size);
}

/// Stops the run with a reason (libFuzzer saves the input as a crash artifact).
[[noreturn]] inline void fail(const std::string& why) {
    std::fprintf(stderr, "FUZZ FINDING: %s\n", why.c_str());
    std::fflush(stderr);
    std::abort();
}

/// A refusal must say which input it refuses.
inline void expectNamed(const std::exception& e, std::string_view name) {
    const std::string_view what = e.what();
    if (what.find(name) == std::string_view::npos)
        fail("refusal does not name the input \"" + std::string(name) + "\": " + std::string(what));
}

/// Runs `read`; a refusal of type Refusal naming `name` is fine, anything else is a finding.
template <typename Refusal, typename Read>
void expectReadOrRefusal(std::string_view name, Read&& read) {
    try {
        read();
    } catch (const Refusal& e) {
        expectNamed(e, name);
    } catch (const std::exception& e) {
        fail(std::string("unexpected exception ") + typeid(e).name() + ": " + e.what());
    }
}

/// A scratch folder of this process (on tmpfs when there is one), removed at exit.
inline const std::filesystem::path& scratchDir() {
    static const std::filesystem::path dir = [] {
        namespace fs = std::filesystem;
        const fs::path base =
            fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
        fs::path d = base / ("underfoot_fuzz_" + std::to_string(::getpid()));
        fs::create_directories(d);
        static struct Remove {
            fs::path p;
            ~Remove() {
                std::error_code ec;
                fs::remove_all(p, ec);
            }
        } remove{d};
        return d;
    }();
    return dir;
}

/// Writes the input to `scratchDir()/name` (replacing it) and returns the path.
inline std::string writeInput(const std::string& name, const std::uint8_t* data, std::size_t size) {
    const std::string path = (scratchDir() / name).string();
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.close();
    if (!out) fail("cannot write the scratch file " + path);
    return path;
}

/// Copies a file through the stream buffers, which retry a read or write a signal interrupts.
/// libFuzzer's -timeout watchdog raises SIGALRM every timeout/2 + 1 s with a handler installed
/// without SA_RESTART; std::filesystem::copy_file (sendfile) then fails with "Interrupted system
/// call" now and then (a CI run's fuzz_web_request failed so). Stops the run with
/// a finding that names the files when the copy really fails.
inline void copyFile(const std::string& from, const std::string& to) {
    std::ifstream in(from, std::ios::binary);
    if (!in) fail("cannot open " + from + " to copy it");
    std::ofstream out(to, std::ios::binary | std::ios::trunc);
    if (!out) fail("cannot create " + to);
    if (in.peek() != std::ifstream::traits_type::eof()) out << in.rdbuf();
    out.close();
    if (in.bad() || !out) fail("cannot copy " + from + " to " + to);
    std::error_code ecFrom, ecTo;
    const auto sizeFrom = std::filesystem::file_size(from, ecFrom);
    const auto sizeTo = std::filesystem::file_size(to, ecTo);
    if (ecFrom || ecTo || sizeFrom != sizeTo)
        fail("the copy of " + from + " at " + to + " differs in size");
}

} // namespace underfoot::fuzz
