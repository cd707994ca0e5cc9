// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot wade`: wading through water driven by leg gyroscopes (docs/explanation/wading.md),
// offline.
//   wade --depth deep --algo v2 --cadence 63 --seconds 20 -o wade.wav   virtual gait
//   wade --gait recording.csv -o wade.wav                                recorded gait
//   wade --write-gait gait.csv --cadence 63 --seconds 20                 virtual gait as CSV
//   wade --latency [--algo v1] [--filter ...]                            measured latencies
//   wade --depth-table [--seeds 1-10] [--seconds 12]    deep against shallow, every cadence
//   wade --live [--osc 9000] [--settings audio.toml] --depth deep --algo v2 --seconds 60
//        [--record-gait live.csv] [-o live.wav]       live on the audio device: OSC gyroscopes
//                                                     (--osc) or the virtual gait (--cadence)
// Bad arguments exit with status 2 and a message naming the option and what it accepts.
#include "app/cli/CommandRegistry.h"
#include "engine/io/AudioFile.h"
#include "engine/io/AudioRecorder.h"
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/render/AudioFeatures.h"
#include "engine/render/Renderer.h"
#include "engine/scene/LiveEngine.h"
#include "engine/scene/WadingNode.h"
#include "engine/surfaces/Preset.h"
#include "engine/wading/Gait.h"
#include "engine/wading/Wading.h"
#include "engine/wading/WadingLatency.h"

#include <fmt/core.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <thread>

namespace underfoot::cli::wade_command {
namespace {
namespace eng = underfoot::engine;

struct WadeArgs {
    std::string depth = "shallow";
    std::string algo = "v2";
    std::string filter = "butterworth_5hz";
    std::string cadence = "63";
    std::string stride = "0";
    std::string seconds = "20";
    std::string seed = "1";
    std::string rate = "48000";
    std::string gait;
    std::string output;
    std::string writeGait;
    std::string format = "pcm24";
    std::string block = "256";
    bool latency = false;
    bool depthTable = false;
    std::string seeds = "1-10";
    bool report = false;
    bool live = false;
    std::string osc; ///< UDP port of the gyroscopes ("" = virtual gait)
    std::string settings, api, device, recordGait;
};

WadeArgs& args() {
    static WadeArgs a;
    return a;
}

double number(const std::string& option, const std::string& text, double lo, double hi,
              const char* expected) {
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v) || errno == ERANGE ||
        v < lo || v > hi)
        throw UserError(fmt::format("{} \"{}\": expected {}", option, text, expected));
    return v;
}

eng::WadingOptions options(const WadeArgs& a) {
    std::map<std::string, std::string> p{
        {"algorithm", a.algo}, {"filter", a.filter}, {"cadence", a.cadence}, {"seed", a.seed}};
    eng::WadingOptions o;
    try {
        o = eng::wadingOptionsFromParameters(p);
    } catch (const eng::WadingOptionError& e) {
        throw UserError(
            fmt::format("wade: {} (options --algo, --filter, --cadence, --seed)", e.what()));
    }
    o.depth = a.depth; // a name or a preset path (checked when loaded)
    o.strideM = number("--stride", a.stride, 0, 2.5, "a stride in metres, [0.2, 2.5] (0: auto)");
    if (o.strideM > 0 && o.strideM < 0.2)
        throw UserError("--stride \"" + a.stride + "\": expected [0.2, 2.5] m or 0 (auto)");
    o.sampleRateHz = number("--rate", a.rate, 8000, 384000, "a sample rate in [8000, 384000] Hz");
    return o;
}

eng::SampleFormat format(const std::string& f) {
    if (f == "pcm16") return eng::SampleFormat::Pcm16;
    if (f == "pcm24") return eng::SampleFormat::Pcm24;
    if (f == "float") return eng::SampleFormat::Float32;
    throw UserError("--format \"" + f + "\": expected pcm16, pcm24 or float");
}

std::string db(float x) {
    return x > 0 ? fmt::format("{:.1f} dBFS", 20.0 * std::log10(x)) : std::string("silent");
}

/// `wade --live`: the wading node on the audio device, fed by OSC gyroscopes or the virtual gait.
int runLive(const WadeArgs& a, const eng::WadingOptions& o, double seconds) {
    eng::AudioSettings settings;
    try {
        if (!a.settings.empty()) settings = eng::loadAudioSettings(a.settings);
    } catch (const eng::AudioSettingsError& e) {
        throw UserError(std::string("wade --settings: ") + e.what());
    }
    if (!a.api.empty()) settings.api = a.api;
    if (!a.device.empty()) settings.device = a.device;
    std::shared_ptr<eng::OscGyroReceiver> receiver;
    if (!a.osc.empty()) {
        eng::OscGyroConfig config;
        config.port = static_cast<int>(
            number("--osc", a.osc, 1, 65535, "a UDP port in [1, 65535] for the gyroscopes"));
        receiver = std::make_shared<eng::OscGyroReceiver>(config);
    }
    eng::LiveEngine engine;
    try {
        engine.open(settings);
    } catch (const eng::AudioSettingsError& e) {
        throw UserError(std::string("wade --live: ") + e.what());
    }
    const auto spec = engine.processSpec();
    eng::WadingOptions live = o;
    live.sampleRateHz = spec.sampleRateHz;
    std::unique_ptr<eng::GaitSource> source;
    if (receiver) {
        source = std::make_unique<eng::LiveGyroGaitSource>(receiver);
    } else {
        eng::VirtualGaitParameters p;
        p.cadenceStepsPerMin = o.cadenceStepsPerMin;
        p.strideM = o.strideM;
        source = std::make_unique<eng::VirtualGaitSource>(p, std::min(600.0, seconds + 1.0));
    }
    eng::LiveSceneDescription d;
    d.seed = o.seed;
    std::shared_ptr<eng::AudioRecorder> outRecorder;
    if (!a.output.empty())
        d.outputRecorder = outRecorder =
            std::make_shared<eng::AudioRecorder>(a.output, 2, spec.sampleRateHz);
    // Room for the whole trial's gait at 100 Hz (plus slack for late frames).
    d.wading = std::make_unique<eng::WadingNode>(live, std::move(source),
                                                 static_cast<std::size_t>(seconds * 110.0) + 1000);
    auto scene = eng::LiveScene::create(std::move(d), spec, engine.settings().channels);
    scene->setMeasureCost(true);
    fmt::print("device: {} \"{}\", {} Hz, {} frames ({:.2f} ms), {} out / {} in\n",
               engine.openedApi(), engine.openedDevice(), engine.settings().sampleRateHz,
               engine.settings().blockSize,
               1e3 * engine.settings().blockSize / engine.settings().sampleRateHz,
               engine.outputChannels(), engine.inputChannels());
    fmt::print("scene: {}\n", scene->summary());
    if (receiver) {
        receiver->start();
        fmt::print("gyroscopes: OSC on UDP port {} (/underfoot/gyro/<left|right>_<thigh|shank> "
                   ",f deg/s [,i sequence]; docs/reference/sensors.md)\n",
                   receiver->port());
    }
    try {
        engine.start();
    } catch (const eng::AudioSettingsError& e) {
        throw UserError(std::string("wade --live: ") + e.what());
    }
    engine.submit(std::move(scene));
    const auto t0 = std::chrono::steady_clock::now();
    for (int s = 1; s <= static_cast<int>(std::ceil(seconds)); ++s) {
        std::this_thread::sleep_until(t0 +
                                      std::chrono::duration<double>(std::min<double>(s, seconds)));
        const auto m = engine.meters();
        std::string sensor;
        if (receiver) {
            const auto st = receiver->status();
            sensor = fmt::format("  gyro {} {:.0f} pkt/s, {} rejected, {} lost",
                                 eng::sensorStateName(st.state), st.rateHz, st.linesRejected,
                                 st.framesLost);
        }
        fmt::print(
            "{:5.1f} s  L {:>11}  R {:>11}  load {:4.1f} %  xruns {}{}\n",
            std::min<double>(s, seconds), db(m.outputPeak[0]),
            db(m.outputPeak[static_cast<std::size_t>(engine.settings().channels.headphonesRight)]),
            m.loadPercent, m.xruns, sensor);
    }
    engine.submit(nullptr);
    engine.waitIdle(engine.settings().crossfadeMs * 1e-3 + 2.0);
    const auto m = engine.meters();
    const auto retired = engine.takeRetired();
    engine.close();
    if (receiver) receiver->stop();
    if (outRecorder) outRecorder->finish();
    const double audioSeconds = double(m.frames) / engine.settings().sampleRateHz;
    fmt::print("{:.2f} s played: {} blocks, {} xruns; callback load avg {:.2f} %, max {:.1f} %\n",
               audioSeconds, m.blocks, m.xruns, m.averageLoadPercent, m.maxLoadPercent);
    if (!retired.empty() && retired.front()->wading()) {
        const eng::WadingNode& node = *retired.front()->wading();
        fmt::print("gait: {} frames applied, {} recorded, {} beyond the recording's capacity, "
                   "{} readings rejected\n",
                   node.framesApplied(), node.recordedFrames(), node.unrecordedFrames(),
                   node.scene().rejectedReadings());
        if (!a.recordGait.empty()) {
            node.writeRecording(a.recordGait);
            fmt::print("gait recorded: {} (re-render: underfoot wade --gait {} --depth {} --algo "
                       "{} --seed {} -o FILE.wav)\n",
                       a.recordGait, a.recordGait, o.depth, o.algorithm, o.seed);
        }
    }
    if (outRecorder)
        fmt::print("output recorded: {} ({} frames, {} dropped)\n", outRecorder->path(),
                   outRecorder->writtenFrames(), outRecorder->droppedFrames());
    return 0;
}

// Seeds given as "A-B" or "A,B,C".
std::vector<std::uint64_t> seedList(const std::string& text) {
    std::vector<std::uint64_t> out;
    const auto dash = text.find('-');
    auto one = [&](const std::string& t) {
        return static_cast<std::uint64_t>(
            number("--seeds", t, 0, 1e9, "seeds as A-B or A,B,C (integers in [0, 1e9])"));
    };
    if (dash != std::string::npos) {
        const auto lo = one(text.substr(0, dash)), hi = one(text.substr(dash + 1));
        if (hi < lo || hi - lo > 1000)
            throw UserError("--seeds \"" + text +
                            "\": expected A-B with A <= B, at most 1001 seeds");
        for (auto s = lo; s <= hi; ++s) out.push_back(s);
        return out;
    }
    std::size_t start = 0;
    while (start <= text.size()) {
        const auto comma = text.find(',', start);
        out.push_back(one(text.substr(start, comma - start)));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return out;
}

/// `wade --depth-table`: deep against shallow water at the studies' three cadences, both
/// algorithms, every seed; prints the Markdown table of docs/explanation/wading.md.
int runDepthTable(const WadeArgs& a, eng::WadingOptions o, double seconds) {
    const auto seeds = seedList(a.seeds);
    fmt::print("Deep against shallow water, {} s of virtual gait, seeds {} ({} each); level = RMS "
               "over the whole render (Leq, dBFS), median over the seeds\n\n",
               seconds, a.seeds, seeds.size());
    fmt::print("| algorithm | cadence (steps/min) | shallow Leq | deep Leq | deep - shallow: min / "
               "median / max (dB) | shallow centroid | deep centroid |\n");
    fmt::print("|---|---:|---:|---:|---|---:|---:|\n");
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        const auto n = v.size();
        return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    };
    for (const char* algo : {"v1", "v2"})
        for (double cadence : {eng::kSlowCadence, eng::kNormalCadence, eng::kFastCadence}) {
            std::vector<double> sh, dp, diff, shc, dpc;
            for (auto seed : seeds) {
                o.algorithm = algo;
                o.cadenceStepsPerMin = cadence;
                o.seed = seed;
                const auto c = eng::measureDepthContrast(o, seconds);
                sh.push_back(c.shallow.leqDb);
                dp.push_back(c.deep.leqDb);
                diff.push_back(c.contrastDb());
                shc.push_back(c.shallow.centroidHz);
                dpc.push_back(c.deep.centroidHz);
            }
            fmt::print("| {} | {:.0f} | {:.1f} | {:.1f} | {:.1f} / {:.1f} / {:.1f} | {:.0f} Hz | "
                       "{:.0f} Hz |\n",
                       algo, cadence, median(sh), median(dp),
                       *std::min_element(diff.begin(), diff.end()), median(diff),
                       *std::max_element(diff.begin(), diff.end()), median(shc), median(dpc));
        }
    return 0;
}

int runWade(const WadeArgs& a) {
    const eng::WadingOptions o = options(a);
    const double seconds =
        number("--seconds", a.seconds, 0.01, 3600, "a duration in (0, 3600] seconds");
    if (!a.live && (!a.osc.empty() || !a.settings.empty() || !a.recordGait.empty()))
        throw UserError("wade: --osc, --settings and --record-gait need --live");
    try {
        if (a.live) {
            if (!a.gait.empty() || a.latency || !a.writeGait.empty())
                throw UserError("wade --live: --gait, --latency and --write-gait are offline "
                                "options (use --osc PORT for live gyroscopes)");
            return runLive(a, o, seconds);
        }
        if (a.depthTable) return runDepthTable(a, o, seconds);
        if (a.latency) {
            const int block = static_cast<int>(
                number("--block", a.block, 1, 8192, "an audio block size in [1, 8192] samples"));
            const auto r = eng::measureWadingLatency(o, block);
            fmt::print("wade latency: depth {}, algorithm {}, filter {}, {} Hz, block {} "
                       "samples ({:.2f} ms), sensor frames every {:.0f} ms\n",
                       o.depth, o.algorithm, o.filter, o.sampleRateHz, block, r.blockMs,
                       r.framePeriodMs);
            fmt::print("  plumbing: frame arrival -> first changed sample  {:7.2f} ms\n",
                       r.firstChangeMs);
            fmt::print("            frame arrival -> first sample > -60 dBFS {:7.2f} ms\n",
                       r.firstAudibleMs);
            fmt::print("  dynamics: frame arrival -> within 6 dB of settled {:7.2f} ms\n",
                       r.withinSixDbMs);
            fmt::print("  low-pass group delay: {:.1f} ms at 0 Hz, {:.1f} ms at 1 Hz (left "
                       "thigh); right thigh {:.1f} ms at 0 Hz\n",
                       r.groupDelayDcMs, r.groupDelay1HzMs, r.rightGroupDelayDcMs);
            return 0;
        }
        if (!a.writeGait.empty()) {
            if (!a.gait.empty())
                throw UserError("wade: --write-gait writes the virtual gait; do not give --gait");
            eng::VirtualGaitParameters p;
            p.cadenceStepsPerMin = o.cadenceStepsPerMin;
            p.strideM = o.strideM;
            const auto frames = eng::virtualGait(p, seconds, o.seed);
            eng::writeGaitCsv(a.writeGait, frames);
            fmt::print("wrote {}: {} frames at 100 Hz ({} s), cadence {} steps/min, stride {:.2f} "
                       "m, seed {}\n",
                       a.writeGait, frames.size(), seconds, o.cadenceStepsPerMin,
                       p.effectiveStrideM(), o.seed);
            if (a.output.empty()) return 0;
        }
        if (a.output.empty())
            throw UserError("wade: -o FILE.wav is required (or --write-gait FILE.csv, --latency)");
        const eng::SampleFormat fmtOut = format(a.format);
        const double cpu0 = eng::threadCpuSeconds();
        eng::AudioBuffer audio;
        eng::LimiterReport limited;
        std::string source;
        if (!a.gait.empty()) {
            bool shanks = true;
            const auto frames = eng::readGaitCsv(a.gait, &shanks);
            if (!shanks && o.algorithm == "v2")
                fmt::print(stderr,
                           "underfoot: warning: {} has no shank columns; algorithm v2 "
                           "hears only the thighs (bubbling and splash stay silent)\n",
                           a.gait);
            audio = eng::renderWading(o, frames, &limited);
            source = a.gait;
        } else {
            audio = eng::renderWading(o, seconds, &limited);
            eng::VirtualGaitParameters p;
            p.cadenceStepsPerMin = o.cadenceStepsPerMin;
            p.strideM = o.strideM;
            source = fmt::format("virtual gait, cadence {} steps/min, stride {:.2f} m",
                                 o.cadenceStepsPerMin, p.effectiveStrideM());
        }
        const double cpu = eng::threadCpuSeconds() - cpu0;
        if (limited.acted())
            fmt::print(stderr,
                       "underfoot: note: the output safety limiter acted on {} samples (up to "
                       "{:.2f} dB of gain reduction)\n",
                       limited.samplesLimited, limited.maxReductionDb);
        eng::writeAudioFile(a.output, audio, fmtOut);
        fmt::print("wrote {}: {:.2f} s stereo at {} Hz; depth {}, algorithm {}, filter {}, seed "
                   "{}; {}\n",
                   a.output, audio.durationSeconds(), o.sampleRateHz, o.depth, o.algorithm,
                   o.filter, o.seed, source);
        if (a.report) {
            const auto f = eng::computeFeatures(audio);
            fmt::print("  peak {:.1f} dBFS, Leq {:.1f} dBFS, RMS {:.1f} dBFS (active frames), "
                       "centroid {:.0f} Hz, "
                       "low share {:.2f}, high share {:.2f}; {:.1f}x real time ({:.3f} s CPU)\n",
                       f.peakDb, f.leqDb, f.rmsDb, f.centroidHz, f.lowShare, f.highShare,
                       cpu > 0 ? audio.durationSeconds() / cpu : 0.0, cpu);
        }
    } catch (const eng::WadingOptionError& e) {
        throw UserError(e.what());
    } catch (const eng::PresetError& e) {
        throw UserError(fmt::format("--depth: {}", e.what()));
    } catch (const eng::GaitFileError& e) {
        throw UserError(fmt::format("--gait: {}", e.what()));
    } catch (const eng::FileError& e) {
        throw UserError(e.what());
    } catch (const eng::SensorError& e) {
        throw UserError(fmt::format("wade --osc: {}", e.what()));
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
    return 0;
}

const CommandRegistrar registrar{
    "wade", [](CLI::App& app, int& exitCode) {
        WadeArgs& a = args();
        auto* cmd = app.add_subcommand(
            "wade", "Wading through water driven by leg gyroscopes (virtual or recorded gait)");
        cmd->add_option("--depth", a.depth, "shallow (ankle), deep (thigh) or a preset .toml");
        cmd->add_option("--algo,--algorithm", a.algo, "v1 (thigh only) or v2 (thigh + shank)");
        cmd->add_option("--filter", a.filter,
                        "gyroscope low-pass: butterworth_5hz, butterworth_0_8hz or asymmetric");
        cmd->add_option("--cadence", a.cadence,
                        "virtual gait: slow (27), normal (63), fast (118) or steps/min; 0 stands");
        cmd->add_option("--stride", a.stride,
                        "virtual gait stride in metres (default 0: from the cadence)");
        cmd->add_option("--seconds", a.seconds, "duration of the virtual gait (default 20)");
        cmd->add_option("--seed", a.seed, "seed of the gait variability and the layers");
        cmd->add_option("--rate", a.rate, "output sample rate in Hz (default 48000)");
        cmd->add_option("--gait", a.gait, "recorded gait CSV (time_s, left/right thigh/shank)");
        cmd->add_option("-o,--output", a.output, "output .wav or .flac");
        cmd->add_option("--format", a.format, "pcm24 (default), pcm16 or float");
        cmd->add_option("--write-gait", a.writeGait, "write the virtual gait as CSV");
        cmd->add_flag("--latency", a.latency, "measure the latency from a gyroscope frame");
        cmd->add_flag("--depth-table", a.depthTable,
                      "deep against shallow water at 27, 63 and 118 steps/min, v1 and v2, over "
                      "--seeds (a Markdown table; --seconds sets the render length)");
        cmd->add_option("--seeds", a.seeds,
                        "with --depth-table: seeds A-B or A,B,C (default 1-10)");
        cmd->add_option("--block", a.block, "audio block size for --latency (default 256)");
        cmd->add_flag("--report", a.report, "print level, spectral centroid and CPU cost");
        cmd->add_flag("--live", a.live,
                      "play live on the audio device (virtual gait, or gyroscopes with --osc)");
        cmd->add_option("--osc", a.osc, "live: UDP port of the OSC gyroscopes (e.g. 9000)");
        cmd->add_option("--settings", a.settings,
                        "live: audio settings file (underfoot devices --save)");
        cmd->add_option("--api", a.api, "live: override the settings' audio API");
        cmd->add_option("--device", a.device, "live: override the settings' device");
        cmd->add_option("--record-gait", a.recordGait,
                        "live: write the trial's gait frames to this CSV (re-render with --gait)");
        cmd->callback([&exitCode, &a] { exitCode = runWade(a); });
    }};

} // namespace
} // namespace underfoot::cli::wade_command
