// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot grf`: ground reaction force (GRF) signals.
//   grf walker  --walker SPEC --seconds S -o walk.wav     two-foot GRF of the virtual walker
//   grf extract -i footstep.wav --peak 800 -o grf.wav     Cook's envelope of a recorded footstep
//   grf bank    -o engine/data/grf [--count 5]            heel/toe bank for sensor triggering
//   grf info    FILE                                      channels, duration, peaks, steps
// GRF files are float WAVs whose samples are newtons / full scale (default 1000 N), as read by
// loadGrfFile (engine/control/GrfFile.h).
#include "app/cli/CommandRegistry.h"
#include "base/Plural.h"
#include "engine/control/CookEnvelope.h"
#include "engine/control/GrfBank.h"
#include "engine/control/GrfFile.h"
#include "engine/control/VirtualWalker.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace underfoot::cli::grf_command {
namespace {

using namespace underfoot::engine;
using underfoot::cli::UserError;

struct Options {
    std::string walker = "cadence=100,mass=70,shoe=0.5,variability=0.03";
    double seconds = 10;
    std::uint64_t seed = 1;
    double rateHz = 48000;
    double fullScaleN = 1000;
    std::string output;
    std::string input;
    double peakN = 800;
    double attackMs = CookEnvelopeSettings{}.attackMs;
    double releaseMs = CookEnvelopeSettings{}.releaseMs;
    int count = 5;
    double massKg = 70;
};

Options& opts() {
    static Options o;
    return o;
}

WalkerParameters parseWalker(const std::string& spec) {
    try {
        return WalkerParameters::parse(spec);
    } catch (const std::invalid_argument& e) {
        throw UserError(fmt::format("--walker: {}", e.what()));
    }
}

template <typename F>
void userErrors(F&& f) {
    try {
        f();
    } catch (const FileError& e) {
        throw UserError(e.what());
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
}

int walkerCommand(const Options& o) {
    const WalkerParameters p = parseWalker(o.walker);
    if (!(o.seconds > 0 && o.seconds <= 3600))
        throw UserError(fmt::format("--seconds {}: expected (0, 3600]", o.seconds));
    userErrors([&] {
        VirtualWalker w(p);
        w.prepare({o.rateHz, 4096});
        w.reset(o.seed);
        GrfSignal g;
        g.sampleRateHz = o.rateHz;
        g.names = {"left", "right"};
        const auto n = static_cast<std::size_t>(std::llround(o.seconds * o.rateHz));
        g.channels.assign(2, std::vector<float>(n));
        w.process(g.channels[0].data(), g.channels[1].data(), static_cast<int>(n));
        writeGrfWav(o.output, g, o.fullScaleN);
        fmt::print("wrote {}: {} s of {} (seed {}), left/right in newtons / {} N\n", o.output,
                   o.seconds, p.toString(), o.seed, o.fullScaleN);
    });
    return 0;
}

int extractCommand(const Options& o) {
    userErrors([&] {
        CookEnvelopeSettings s;
        s.attackMs = o.attackMs;
        s.releaseMs = o.releaseMs;
        const GrfSignal g = grfFromFootstepFile(o.input, o.peakN, o.rateHz, s);
        writeGrfWav(o.output, g, o.fullScaleN);
        fmt::print("wrote {}: Cook envelope of {} (attack {} ms, release {} ms), peak {} N, "
                   "{:.3f} s\n",
                   o.output, o.input, s.attackMs, s.releaseMs, o.peakN, g.durationSeconds());
    });
    return 0;
}

int bankCommand(const Options& o) {
    const WalkerParameters p = parseWalker(o.walker);
    userErrors([&] {
        const GrfBank bank = makeGrfBank(p, o.count, o.seed, o.rateHz);
        std::filesystem::create_directories(o.output);
        for (int i = 0; i < o.count; ++i) {
            const auto k = static_cast<std::size_t>(i);
            for (const auto& [kind, sig] :
                 {std::pair{"heel", &bank.heel[k]}, std::pair{"toe", &bank.toe[k]}}) {
                const auto path =
                    (std::filesystem::path(o.output) / fmt::format("{}_{}.wav", kind, i + 1))
                        .string();
                writeGrfWav(path, *sig, o.fullScaleN);
                const auto& x = sig->channels[0];
                fmt::print("wrote {}: {:.3f} s, peak {:.1f} N\n", path, sig->durationSeconds(),
                           *std::max_element(x.begin(), x.end()));
            }
        }
    });
    return 0;
}

int infoCommand(const Options& o) {
    userErrors([&] {
        GrfLoadOptions lo;
        lo.targetRateHz = o.rateHz;
        lo.fullScaleNewtons = o.fullScaleN;
        lo.bodyMassKg = o.massKg;
        lo.tare = GrfTareMode::Measure; // what `render --grf` and `live --grf` will take off
        const GrfSignal g = loadGrfFile(o.input, lo);
        const std::vector<GrfTare>& tare = g.tare;
        fmt::print("{}: {} at {:.0f} Hz, {:.3f} s\n", o.input,
                   counted(g.channels.size(), "channel"), g.sampleRateHz, g.durationSeconds());
        for (std::size_t c = 0; c < g.channels.size(); ++c) {
            const auto& x = g.channels[c];
            const float peak = x.empty() ? 0.0f : *std::max_element(x.begin(), x.end());
            // Contacts: rises through 5 % of the channel's peak.
            int contacts = 0;
            bool on = false;
            double sum = 0;
            for (float v : x) {
                sum += v;
                if (!on && v > 0.05f * peak)
                    on = true, ++contacts;
                else if (on && v < 0.02f * peak)
                    on = false;
            }
            fmt::print("  {:<8} peak {:8.1f} N ({:.2f} body weights of {} kg), mean {:7.1f} N, "
                       "{}\n",
                       g.names[c], peak, peak / (o.massKg * kGravity), o.massKg,
                       x.empty() ? 0.0 : sum / static_cast<double>(x.size()),
                       counted(contacts, "contact"));
            if (c < tare.size()) {
                const GrfTare& t = tare[c];
                if (t.subtractedN > 0.0)
                    fmt::print("           force-plate zero {:+.1f} N, noise {:.1f} N rms: render "
                               "and live --grf take {:.1f} N off (--no-grf-tare: nothing)\n",
                               t.levelN, t.noiseN, t.subtractedN);
                else if (t.noiseN == 0.0 && t.levelN == 0.0 && t.samplesNearZero >= 50)
                    fmt::print("           clean zero (exact 0 N in the air): nothing to take "
                               "off\n");
                else
                    fmt::print("           no force-plate zero taken off (level {:+.1f} N, noise "
                               "{:.1f} N rms from {} samples near 0 N: too few, or too large "
                               "to be the plate's)\n",
                               t.levelN, t.noiseN, t.samplesNearZero);
            }
        }
    });
    return 0;
}

const underfoot::cli::CommandRegistrar registrar{
    "grf", [](CLI::App& app, int& exitCode) {
        Options& o = opts();
        auto* cmd = app.add_subcommand("grf", "Ground reaction force signals: walker, extract, "
                                              "bank, info");
        cmd->require_subcommand(1);
        auto addCommon = [&o](CLI::App* sub) {
            sub->add_option("--rate", o.rateHz, "sample rate in Hz (default 48000)");
            sub->add_option("--full-scale", o.fullScaleN,
                            "newtons of a WAV sample of 1.0 (default 1000)");
        };
        auto* walker =
            cmd->add_subcommand("walker", "Write the virtual walker's GRF (left, right)");
        walker->add_option("--walker", o.walker,
                           "e.g. cadence=100,mass=70,shoe=0.5,variability=0.03");
        walker->add_option("--seconds", o.seconds, "duration (default 10)");
        walker->add_option("--seed", o.seed, "seed (default 1)");
        walker->add_option("-o,--output", o.output, "output .wav")->required();
        addCommon(walker);
        walker->callback([&exitCode, &o] { exitCode = walkerCommand(o); });

        auto* extract = cmd->add_subcommand(
            "extract", "GRF of a recorded footstep (Cook's envelope of the loudest channel)");
        extract->add_option("-i,--input", o.input, "recorded footstep (WAV/FLAC/OGG)")->required();
        extract->add_option("--peak", o.peakN, "peak force in newtons (default 800)");
        extract->add_option("--attack-ms", o.attackMs, "99 % rise time (default 1 ms)");
        extract->add_option("--release-ms", o.releaseMs, "99 % fall time (default 100 ms)");
        extract->add_option("-o,--output", o.output, "output .wav")->required();
        addCommon(extract);
        extract->callback([&exitCode, &o] { exitCode = extractCommand(o); });

        auto* bank = cmd->add_subcommand(
            "bank", "Write heel_N.wav and toe_N.wav GRFs from walker stances (sensor triggering)");
        bank->add_option("-o,--output", o.output, "output folder")->required();
        bank->add_option("--count", o.count, "GRFs of each kind (default 5)");
        bank->add_option("--walker", o.walker, "walker parameters (use some variability)");
        bank->add_option("--seed", o.seed, "seed (default 1)");
        addCommon(bank);
        bank->callback([&exitCode, &o] { exitCode = bankCommand(o); });

        auto* info = cmd->add_subcommand("info", "Load a GRF file (WAV or CSV) and summarise it");
        info->add_option("file", o.input, "GRF file")->required();
        info->add_option("--mass", o.massKg, "body mass for *_bw CSV columns (default 70 kg)");
        addCommon(info);
        info->callback([&exitCode, &o] { exitCode = infoCommand(o); });
    }};

} // namespace
} // namespace underfoot::cli::grf_command
