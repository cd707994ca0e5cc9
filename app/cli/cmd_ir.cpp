// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot ir`: room impulse responses for the "with reverb" surfaces.
//   ir generate --room wooden_room -o wooden_room.wav [--seed 1] [--rate 48000] [--seconds S]
//   ir list                       built-in rooms and the IRs shipped in engine/data/ir
//   ir measure FILE|NAME          T30 per octave band (Schroeder backward integration)
#include "app/cli/CommandRegistry.h"
#include "engine/dsp/Biquad.h"
#include "engine/io/AudioFile.h"
#include "engine/reverb/ImpulseResponses.h"
#include "engine/reverb/RoomModel.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace {

using namespace underfoot::engine;
using underfoot::cli::UserError;

struct Options {
    std::string room;
    std::string output;
    std::uint64_t seed = 1;
    double rateHz = 48000;
    double seconds = 0;
    bool mono = false;
    std::string measureTarget;
};

Options& opts() {
    static Options o;
    return o;
}

int generate(const Options& o) {
    RoomSpec room;
    try {
        room = roomPreset(o.room);
    } catch (const std::invalid_argument& e) {
        throw UserError(fmt::format("--room: {}", e.what()));
    }
    RoomIrOptions ro;
    ro.seed = o.seed;
    ro.sampleRateHz = o.rateHz;
    ro.lengthSeconds = o.seconds;
    ro.channels = o.mono ? 1 : 2;
    AudioBuffer ir;
    try {
        ir = generateRoomImpulseResponse(room, ro);
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
    try {
        writeAudioFile(o.output, ir, SampleFormat::Pcm24);
    } catch (const FileError& e) {
        throw UserError(e.what());
    }
    fmt::print("wrote {}: {} ({} ch, {:.0f} Hz, {:.3f} s, seed {})\n", o.output, room.description,
               ir.channels, ir.sampleRateHz, ir.durationSeconds(), o.seed);
    return 0;
}

int list() {
    fmt::print("Rooms (underfoot ir generate --room NAME):\n");
    for (const auto& name : roomPresetNames()) {
        const RoomSpec r = roomPreset(name);
        fmt::print("  {:<12} {}; T60 per octave 125 Hz..8 kHz:", name, r.description);
        for (double t : r.t60Seconds) fmt::print(" {:.2f}", t);
        fmt::print(" s\n");
    }
    fmt::print("Shipped impulse responses ({}):\n", impulseResponseDirectory());
    for (const auto& name : availableImpulseResponses()) fmt::print("  {}\n", name);
    return 0;
}

int measure(const Options& o) {
    AudioBuffer ir;
    try {
        ir = readAudioFile(findImpulseResponse(o.measureTarget));
    } catch (const FileError& e) {
        throw UserError(e.what());
    }
    fmt::print("{}: {} ch, {:.0f} Hz, {:.3f} s\n", o.measureTarget, ir.channels, ir.sampleRateHz,
               ir.durationSeconds());
    fmt::print("T30 (Schroeder, -5..-35 dB), energy of all channels summed; octave filters: "
               "3rd-order Butterworth per edge\n");
    fmt::print("  {:>8}  {:>8}\n", "band Hz", "T30 s");
    auto t30 = [&](double fc) -> std::string {
        std::vector<float> sum(ir.frames(), 0.0f);
        for (int c = 0; c < ir.channels; ++c) {
            auto x = ir.channel(c);
            if (fc > 0) {
                Butterworth bp;
                bp.design(FilterType::Bandpass, 3, ir.sampleRateHz, fc / std::sqrt(2.0),
                          std::min(fc * std::sqrt(2.0), 0.45 * ir.sampleRateHz));
                bp.process(x.data(), static_cast<int>(x.size()));
            }
            for (std::size_t i = 0; i < x.size(); ++i) sum[i] = std::hypot(sum[i], x[i]);
        }
        try {
            return fmt::format("{:.3f}", schroederT60Seconds(sum, ir.sampleRateHz));
        } catch (const std::invalid_argument&) {
            return "n/a (decay does not reach -35 dB)";
        }
    };
    for (double fc : kOctaveBandCentersHz)
        if (fc * std::sqrt(2.0) < 0.5 * ir.sampleRateHz)
            fmt::print("  {:>8.0f}  {:>8}\n", fc, t30(fc));
    fmt::print("  {:>8}  {:>8}\n", "broad", t30(0));
    return 0;
}

const underfoot::cli::CommandRegistrar registrar{
    "ir", [](CLI::App& app, int& exitCode) {
        Options& o = opts();
        auto* cmd = app.add_subcommand("ir", "Room impulse responses: generate, list, measure");
        cmd->require_subcommand(1);
        auto* gen = cmd->add_subcommand(
            "generate", "Render a room's impulse response to a 24-bit WAV/FLAC file");
        gen->add_option("--room", o.room, "room preset (see `underfoot ir list`)")->required();
        gen->add_option("-o,--output", o.output, "output .wav or .flac file")->required();
        gen->add_option("--seed", o.seed, "seed of the late-tail noise (default 1)");
        gen->add_option("--rate", o.rateHz, "sample rate in Hz (default 48000)");
        gen->add_option("--seconds", o.seconds,
                        "length in seconds (default: 1.1 x the longest octave-band T60)");
        gen->add_flag("--mono", o.mono, "one channel at the listener position (default: 2 ears)");
        gen->callback([&exitCode, &o] { exitCode = generate(o); });
        auto* ls = cmd->add_subcommand("list", "List room presets and shipped impulse responses");
        ls->callback([&exitCode] { exitCode = list(); });
        auto* ms = cmd->add_subcommand("measure", "Measure T30 per octave band of an IR");
        ms->add_option("ir", o.measureTarget, "IR file or shipped name")->required();
        ms->callback([&exitCode, &o] { exitCode = measure(o); });
    }};

} // namespace
