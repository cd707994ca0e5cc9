// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot export`: the long-format trials CSV (one row per trial), the ratings CSV, the
// participants and scales tables, and the codebook of a study.
#include "app/cli/CommandRegistry.h"
#include "base/Plural.h"
#include "experiment/Export.h"
#include "experiment/Store.h"

#include <fmt/core.h>

#include <filesystem>
#include <fstream>

namespace underfoot::cli::export_command {
namespace {

using namespace underfoot::experiment;
using underfoot::cli::UserError;

struct Options {
    std::string study;
    std::string outDir = ".";
    bool all = false;
};

Options& opts() {
    static Options o;
    return o;
}

std::ofstream openOut(const std::filesystem::path& path) {
    std::ofstream out(path, std::ios::binary);
    if (!out) throw UserError(fmt::format("{}: cannot write the file", path.string()));
    return out;
}

const underfoot::cli::CommandRegistrar registrar{
    "export", [](CLI::App& app, int& exitCode) {
        Options& o = opts();
        auto* cmd =
            app.add_subcommand("export", "Write trials.csv (one row per trial), ratings.csv, "
                                         "participants.csv, scales.csv, audio.csv and codebook.md");
        cmd->add_option("--study", o.study, "study file")->required();
        cmd->add_option("-o,--out", o.outDir, "output folder (created if needed)");
        cmd->add_flag("--all-trials", o.all, "also write planned trials not answered yet");
        cmd->callback([&exitCode, &o] {
            try {
                StudyStore store = StudyStore::openForReading(o.study);
                std::filesystem::create_directories(o.outDir);
                const std::filesystem::path dir(o.outDir);
                const ExportScope scope = o.all ? ExportScope::All : ExportScope::Answered;
                auto trials = openOut(dir / "trials.csv");
                const int rows = writeTrialsCsv(store, trials, scope);
                auto ratings = openOut(dir / "ratings.csv");
                const int ratingRows = writeRatingsCsv(store, ratings, scope);
                auto participants = openOut(dir / "participants.csv");
                const int participantRows = writeParticipantsCsv(store, participants);
                auto scales = openOut(dir / "scales.csv");
                const int scaleRows = writeScalesCsv(store, scales);
                auto audio = openOut(dir / "audio.csv");
                const int audioRows = writeAudioCsv(store, audio, scope);
                auto codebook = openOut(dir / "codebook.md");
                writeCodebook(store, codebook);
                trials.close();
                ratings.close();
                participants.close();
                scales.close();
                codebook.close();
                audio.close();
                if (!trials || !ratings || !participants || !scales || !codebook || !audio)
                    throw UserError(fmt::format("{}: writing the export failed", o.outDir));
                fmt::print("wrote {}, {}, {}, {}, {} and the codebook to {}\n",
                           counted(rows, "trial row"), counted(ratingRows, "rating row"),
                           counted(participantRows, "participant"), counted(scaleRows, "scale"),
                           counted(audioRows, "audio row"), o.outDir);
            } catch (const StoreError& e) {
                throw UserError(e.what());
            } catch (const std::filesystem::filesystem_error& e) {
                throw UserError(e.what());
            }
            exitCode = 0;
        });
    }};

} // namespace
} // namespace underfoot::cli::export_command
