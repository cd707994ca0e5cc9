// SPDX-License-Identifier: GPL-3.0-or-later
// The program's version (CMake's project version) and the git commit it was built from. Both
// live in one generated translation unit (cmake/VersionStamp.cmake writes it at every build,
// and rewrites it only when the commit changed), so a new commit recompiles one file.
#pragma once

namespace underfoot::base {

/// "0.1.0": the version stored with every study and fit.
const char* version();

/// The commit, 12 hex digits with "-dirty" when the work tree had changes, or "unknown" when
/// built outside a git checkout (e.g. from a source archive).
const char* gitCommit();

/// "0.1.0 (commit 0123456789ab)": what `--version` prints after the program's name.
const char* versionLine();

} // namespace underfoot::base
