// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot ir`: room impulse responses for the "with reverb" surfaces.
//   ir generate --room wooden_room -o wooden_room.wav [--seed 1] [--rate 48000] [--seconds S]
//   ir list                       built-in rooms and the IRs shipped in engine/data/ir
//   ir measure FILE|NAME          T30 per octave band (Schroeder backward integration)
//   ir cost FILE|NAME [--block N] CPU cost of the zero-latency Convolver with that IR
#include "app/cli/CommandRegistry.h"
#include "engine/dsp/Biquad.h"
#include "engine/dsp/Denormals.h"
#include "engine/dsp/Random.h"
#include "engine/io/AudioFile.h"
#include "engine/reverb/Convolver.h"
#include "engine/reverb/ImpulseResponses.h"
#include "engine/reverb/RoomModel.h"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>

namespace underfoot::cli::ir_command {
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
    int block = 256;
    double costSeconds = 30;
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

int cost(const Options& o) {
    if (o.block < 1 || o.block > 8192)
        throw UserError(fmt::format("--block {}: expected 1..8192", o.block));
    if (!(o.costSeconds >= 1 && o.costSeconds <= 600))
        throw UserError(fmt::format("--seconds {}: expected 1..600", o.costSeconds));
    AudioBuffer ir;
    try {
        ir = readAudioFile(findImpulseResponse(o.measureTarget));
    } catch (const FileError& e) {
        throw UserError(e.what());
    }
    const double fs = 48000;
    Convolver conv;
    conv.prepare(ir, fs, o.block);
    ScopedFlushDenormals flush;
    Random r(1);
    const auto blocks = static_cast<std::size_t>(o.costSeconds * fs / o.block);
    const auto n = static_cast<std::size_t>(o.block);
    std::vector<float> in(blocks * n), l(n), rr(n);
    for (auto& v : in) v = static_cast<float>(0.1 * r.bipolar());
    // Thread CPU time (CLOCK_THREAD_CPUTIME_ID): other processes on a shared machine do not
    // inflate it; the wall-clock total is printed too.
    auto cpuNow = [] {
        timespec ts{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
        return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
    };
    std::vector<double> times(blocks);
    const auto wall0 = std::chrono::steady_clock::now();
    for (std::size_t b = 0; b < blocks; ++b) {
        const double t0 = cpuNow();
        conv.process(in.data() + b * n, l.data(), rr.data(), o.block);
        times[b] = cpuNow() - t0;
    }
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    double total = 0;
    for (double t : times) total += t;
    std::vector<double> sorted = times;
    std::sort(sorted.begin(), sorted.end());
    const double budget = static_cast<double>(n) / fs;
    fmt::print("{}: {} taps at 48 kHz, stereo out, FFT stages", o.measureTarget,
               conv.impulseLength());
    for (int p : conv.partitionSizes()) fmt::print(" {}", p);
    fmt::print(" (+ 64 direct taps); {} blocks of {} samples\n", blocks, n);
    fmt::print(
        "  CPU: mean {:.1f} ns/sample = {:.0f}x real time on one core (wall clock: {:.0f}x)\n",
        total / static_cast<double>(blocks * n) * 1e9, o.costSeconds / total, o.costSeconds / wall);
    fmt::print("  CPU per block: median {:.1f} us, 90th percentile {:.1f} us, max {:.1f} us "
               "(budget {:.0f} us)\n",
               sorted[blocks / 2] * 1e6, sorted[blocks * 9 / 10] * 1e6, sorted.back() * 1e6,
               budget * 1e6);
    return 0;
}

const underfoot::cli::CommandRegistrar registrar{
    "ir", [](CLI::App& app, int& exitCode) {
        Options& o = opts();
        auto* cmd =
            app.add_subcommand("ir", "Room impulse responses: generate, list, measure, cost");
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
        auto* cs = cmd->add_subcommand("cost", "Time the zero-latency Convolver with an IR");
        cs->add_option("ir", o.measureTarget, "IR file or shipped name")->required();
        cs->add_option("--block", o.block, "block size in samples (default 256)");
        cs->add_option("--seconds", o.costSeconds, "seconds of audio to process (default 30)");
        cs->callback([&exitCode, &o] { exitCode = cost(o); });
    }};

} // namespace
} // namespace underfoot::cli::ir_command
