// SPDX-License-Identifier: GPL-3.0-or-later
#include "base/DataDir.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

// The three paths below are the only absolute paths of the build compiled into the programs,
// and only into this file (base/CMakeLists.txt): every other object file is the same in any
// checkout, so a compiler cache shares it.
#ifndef UNDERFOOT_SOURCE_DIR
#error "base/CMakeLists.txt defines UNDERFOOT_SOURCE_DIR for this file"
#endif

namespace underfoot::base {
namespace fs = std::filesystem;

namespace {

struct KindInfo {
    const char* env;       ///< the kind's own override
    const char* installed; ///< below share/underfoot
    const char* source;    ///< below the source tree
};

KindInfo info(DataKind kind) {
    switch (kind) {
    case DataKind::Surfaces:
        return {"UNDERFOOT_SURFACES_DIR", "surfaces", "engine/data/surfaces"};
    case DataKind::ImpulseResponses:
        return {"UNDERFOOT_IR_DIR", "ir", "engine/data/ir"};
    case DataKind::GrfBank:
        return {"UNDERFOOT_GRF_BANK_DIR", "grf", "engine/data/grf"};
    case DataKind::WadingPresets:
        return {"UNDERFOOT_WADING_DIR", "wading", "engine/data/wading"};
    case DataKind::Soundscapes:
        return {"UNDERFOOT_SOUNDSCAPES_DIR", "soundscapes", "soundscapes/data"};
    case DataKind::Protocols:
        return {"UNDERFOOT_PROTOCOLS_DIR", "protocols", "protocols"};
    case DataKind::GuiDemo:
        return {"UNDERFOOT_GUI_DATA_DIR", "gui", "app/gui/data"};
    }
    return {"UNDERFOOT_DATA_DIR", "", ""};
}

const char* nonEmptyEnv(const char* name) {
    const char* v = std::getenv(name);
    return v && *v ? v : nullptr;
}

bool isDirectory(const fs::path& p) {
    std::error_code ec;
    return fs::is_directory(p, ec);
}

/// True when `inner` lies below `outer` (both made absolute and normal, not resolved).
bool isBelow(const fs::path& inner, const fs::path& outer) {
    const auto a = inner.lexically_normal(), b = outer.lexically_normal();
    auto i = a.begin();
    for (auto o = b.begin(); o != b.end(); ++o, ++i) {
        if (o->empty()) continue; // the trailing "" of a path ending in '/'
        if (i == a.end() || *i != *o) return false;
    }
    return true;
}

/// The program runs from this build tree (its tests, `build/app/cli/underfoot`).
bool runsFromBuildTree() {
    const std::string exe = executablePath();
    if (exe.empty()) return false;
    std::error_code ec;
    const auto build = fs::weakly_canonical(UNDERFOOT_BINARY_DIR, ec);
    return !ec && isBelow(fs::path(exe), build);
}

} // namespace

std::string executablePath() {
    std::error_code ec;
    const auto p = fs::read_symlink("/proc/self/exe", ec);
    return ec ? std::string() : p.string();
}

const char* dataEnvironmentVariable(DataKind kind) {
    return info(kind).env;
}

std::string dataDirectory(DataKind kind) {
    const KindInfo k = info(kind);
    if (const char* env = nonEmptyEnv(k.env)) return env;
    if (const char* root = nonEmptyEnv("UNDERFOOT_DATA_DIR"))
        return (fs::path(root) / k.installed).string();
    if (const std::string exe = executablePath(); !exe.empty()) {
        const auto installed =
            fs::path(exe).parent_path().parent_path() / "share" / "underfoot" / k.installed;
        if (isDirectory(installed)) return installed.string();
    }
    if (runsFromBuildTree()) return (fs::path(UNDERFOOT_SOURCE_DIR) / k.source).string();
    // The program's own folder could not be read (no /proc in a chroot) or holds no data: the
    // configured prefix, then Debian's and a local install's.
    for (const char* root :
         {UNDERFOOT_INSTALL_DATA_DIR, "/usr/share/underfoot", "/usr/local/share/underfoot"}) {
        const auto dir = fs::path(root) / k.installed;
        if (isDirectory(dir)) return dir.string();
    }
    return (fs::path(UNDERFOOT_INSTALL_DATA_DIR) / k.installed).string();
}

std::string recordingsDirectory() {
    if (const char* env = nonEmptyEnv("UNDERFOOT_RECORDINGS")) return env;
    if (runsFromBuildTree()) return (fs::path(UNDERFOOT_SOURCE_DIR) / "build/recordings").string();
    if (const char* cache = nonEmptyEnv("XDG_CACHE_HOME"))
        return (fs::path(cache) / "underfoot/recordings").string();
    if (const char* home = nonEmptyEnv("HOME"))
        return (fs::path(home) / ".cache/underfoot/recordings").string();
    return "underfoot-recordings";
}

} // namespace underfoot::base
