// SPDX-License-Identifier: GPL-3.0-or-later
// The `underfoot` command line: subcommands register themselves (CommandRegistry.h).
#include "app/cli/CommandRegistry.h"
#include "base/Version.h"
#include "engine/dsp/Simd.h"

#include <fmt/core.h>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
    if (!underfoot::engine::simdEnvironmentValid()) {
        fmt::print(stderr,
                   "underfoot: the environment variable UNDERFOOT_SIMD is set to an unknown "
                   "value; expected sse2 or avx (or unset: the CPU's best)\n");
        return 2;
    }
    CLI::App app{"Underfoot: physically based footsteps and perception experiments"};
    app.set_version_flag("--version", std::string("underfoot ") + underfoot::base::versionLine());
    app.require_subcommand(1);
    int exitCode = 0;
    for (auto& entry : underfoot::cli::commandRegistry()) entry.install(app, exitCode);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    } catch (const underfoot::cli::UserError& e) {
        fmt::print(stderr, "underfoot: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        fmt::print(stderr, "underfoot: error: {}\n", e.what());
        return 1;
    }
    return exitCode;
}
