// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/wiring/Replay.h"

#include "app/wiring/Players.h"
#include "app/wiring/StimulusRender.h"
#include "base/TomlReader.h"
#include "engine/control/GrfFile.h"
#include "engine/render/Renderer.h"
#include "engine/scene/WadingNode.h"
#include "engine/wading/Gait.h"
#include "engine/wading/Wading.h"
#include "experiment/Clips.h"
#include "experiment/Simulation.h"
#include "experiment/Store.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace underfoot::wiring {
namespace {

namespace eng = underfoot::engine;
namespace exp = underfoot::experiment;
namespace fs = std::filesystem;

LiveMeters readMetersFile(const fs::path& recording) {
    const fs::path meters = recording.string() + ".meters.toml";
    if (!fs::exists(meters)) return {};
    std::ifstream in(meters, std::ios::binary);
    if (!in) throw ReplayError(fmt::format("{}: cannot read the meters file", meters.string()));
    std::ostringstream text;
    text << in.rdbuf();
    return parseLiveMeters(text.str(), meters.string());
}

/// A listening-test trial: the clip it played, rendered again from the stimulus, its seed and
/// length through the one renderer (a lab-supplied clip is read from the clip folder), and its
/// samples compared with the SHA-256 stored with the trial.
ReplayRender replayClip(const ReplayRequest& q, const exp::ReplayInfo& info) {
    const exp::PlayedClip& clip = *info.clip;
    ReplayRender out;
    out.seed = info.renderSeed;
    out.clipSha256 = clip.samplesSha256;
    try {
        if (info.stimulus.clip) {
            std::string dir = q.clipsDir;
            if (dir.empty() && info.sensorConfig.rfind("clips ", 0) == 0)
                dir = info.sensorConfig.substr(6);
            if (dir.empty())
                throw ReplayError(fmt::format(
                    "trial {} of {} played the lab-supplied clip `{}`; give the clip folder "
                    "(--clips DIR) to read it back",
                    q.trial + 1, q.participant, clip.file));
            out.audio = eng::readAudioFile((fs::path(dir) / clip.file).string());
        } else {
            if (!(clip.sampleRateHz >= 8000 && clip.sampleRateHz <= 384000) || clip.frames == 0)
                throw ReplayError(fmt::format("trial {} of {}: the stored clip has no usable "
                                              "length or rate ({} frames at {} Hz)",
                                              q.trial + 1, q.participant, clip.frames,
                                              clip.sampleRateHz));
            StimulusRender render;
            render.stimulus = info.stimulus;
            render.seed = info.renderSeed;
            render.sampleRateHz = clip.sampleRateHz;
            render.clipSeconds = static_cast<double>(clip.frames) / clip.sampleRateHz;
            out.audio = renderStimulus(render);
        }
    } catch (const ReplayError&) {
        throw;
    } catch (const std::exception& e) {
        throw ReplayError(e.what());
    }
    out.sampleRateHz = out.audio.sampleRateHz;
    out.blockSize = 256;
    const std::string hash = samplesSha256(out.audio);
    if (!clip.samplesSha256.empty()) out.matchesHeard = hash == clip.samplesSha256;
    out.description = fmt::format(
        "{} trial {} (clip {}): {:.2f} s, seed {}; {}", info.participant, info.trialIndex + 1,
        clip.file, double(out.audio.frames()) / out.sampleRateHz, out.seed,
        !out.matchesHeard ? "no samples hash was stored with the trial (an older study)"
        : *out.matchesHeard
            ? "the samples are those the participant heard (SHA-256 " + hash.substr(0, 12) + ")"
            : "DIFFERENT from the clip the participant heard (SHA-256 " + hash.substr(0, 12) +
                  ", stored " + clip.samplesSha256.substr(0, 12) + ")");
    return out;
}

} // namespace

LiveMeters parseLiveMeters(const std::string& text, const std::string& file) {
    LiveMeters run;
    try {
        const toml::table t = base::parseToml(text, file);
        // The rate and block size the replay runs at: a value it cannot use is refused (naming
        // the file, line and column), never replaced by the replay's defaults. Its other keys
        // (scene, frames, xruns, loads) are the live run's report, not read here.
        base::TomlReader reader(file, base::TomlReader::Mode::Throw);
        run.sampleRateHz = reader.number(t, "sample_rate", "the live meters", 8000.0, 768000.0);
        if (const auto b = reader.integer(t, "block_size", "the live meters", false, 1, 65536))
            run.blockSize = static_cast<int>(*b);
    } catch (const base::TomlError& e) {
        throw ReplayError(e.what());
    }
    return run;
}

ReplayRender renderTrialReplay(const ReplayRequest& q) {
    exp::ReplayInfo info;
    try {
        const auto store = exp::StudyStore::openForReading(q.study);
        info = store.trialForReplay(q.participant, q.trial);
    } catch (const std::exception& e) {
        throw ReplayError(e.what());
    }
    const auto& stimulus = info.stimulus;
    if (info.clip) return replayClip(q, info);
    if (stimulus.clip)
        throw ReplayError(fmt::format(
            "trial {} of {} played the lab-supplied clip `{}` (in the study's clip folder); that "
            "file is what was heard, nothing is rendered for it",
            q.trial + 1, q.participant, *stimulus.clip));
    std::optional<fs::path> recording;
    LiveMeters live;
    // A simulated participant's sensor trial: its feet were a virtual walker whose parameters
    // the trial stores as text.
    std::optional<exp::SimulatedWalker> simulatedWalker;
    if (info.grfRecording) {
        try {
            simulatedWalker = exp::parseSimulatedWalker(*info.grfRecording);
        } catch (const std::invalid_argument& e) {
            throw ReplayError(
                fmt::format("trial {} of {}: {}", q.trial + 1, q.participant, e.what()));
        }
        if (simulatedWalker) info.grfRecording.reset();
    }
    if (info.grfRecording) {
        recording = fs::path(*info.grfRecording);
        if (recording->is_relative()) recording = fs::path(q.study).parent_path() / *recording;
        live = readMetersFile(*recording);
    }
    ReplayRender out;
    out.seed = info.renderSeed;
    out.sampleRateHz = q.sampleRateHz.value_or(live.sampleRateHz.value_or(48000.0));
    out.blockSize = q.blockSize.value_or(live.blockSize.value_or(256));
    const double rate = out.sampleRateHz;
    if (!(rate >= 8000 && rate <= 384000))
        throw ReplayError(fmt::format("sample rate {} Hz: expected 8000 to 384000", rate));
    if (out.blockSize < 1 || out.blockSize > 65536)
        throw ReplayError(fmt::format("block size {}: expected 1 to 65536", out.blockSize));

    try {
        if (!stimulus.wading.empty() || stimulus.surface == "water") {
            // Wading: the recorded gait of a live trial, else the virtual gait of the stimulus.
            eng::WadingOptions options =
                eng::wadingOptionsFromParameters(exp::parameterStrings(stimulus.wading));
            options.seed = info.renderSeed;
            options.sampleRateHz = rate;
            std::string source;
            const fs::path arrivals =
                recording ? fs::path(recording->string() + ".arrivals.csv") : fs::path();
            if (recording && fs::exists(arrivals)) {
                // Each frame at the sample where the live node applied it, at the live block
                // size: the samples the node rendered.
                out.audio = eng::renderWadingArrivals(
                    options, eng::readGaitArrivals(arrivals.string()), out.blockSize);
                source = fmt::format("recorded gait arrivals {} (block {})", arrivals.string(),
                                     out.blockSize);
            } else if (recording) {
                // An older trial (no arrivals file): the gait on its 100 Hz grid, which only
                // approximates where the live frames took effect.
                out.audio = eng::renderWading(options, eng::readGaitCsv(recording->string()));
                source = "recorded gait " + recording->string() +
                         " on its 100 Hz grid (no arrivals file: not sample-exact)";
            } else {
                StimulusRender render;
                render.stimulus = stimulus;
                render.seed = info.renderSeed;
                render.sampleRateHz = rate;
                render.blockSize = out.blockSize;
                render.walkSeconds = q.walkSeconds;
                out.audio = renderStimulus(render);
                source = fmt::format("virtual gait, {} steps/min", options.cadenceStepsPerMin);
            }
            out.description = fmt::format("{} trial {} (wading): {:.1f} s from {}, seed {}",
                                          info.participant, info.trialIndex + 1,
                                          double(out.audio.frames()) / rate, source, out.seed);
            return out;
        }

        eng::GrfSignal grf;
        std::string source;
        if (recording) {
            eng::GrfLoadOptions options;
            options.targetRateHz = rate;
            try {
                grf = eng::loadGrfFile(recording->string(), options);
            } catch (const std::exception& e) {
                throw ReplayError(std::string("the trial's GRF recording: ") + e.what());
            }
            source = "recorded GRF " + recording->string();
        } else if (simulatedWalker) {
            const auto walker = walkerFromStimulus(simulatedWalker->walker);
            grf = eng::walkerGrf(walker, simulatedWalker->seconds, rate, info.renderSeed);
            source = "the simulated participant's virtual walker " + walker.toString();
        } else if (stimulus.input.kind == exp::InputKind::Walker) {
            const auto walker = walkerFromStimulus(stimulus.input.walker);
            grf = eng::walkerGrf(walker, q.walkSeconds, rate, info.renderSeed);
            source = "virtual walker " + walker.toString();
        } else {
            if (info.audioConfig.rfind("none (data entry", 0) == 0)
                throw ReplayError(fmt::format(
                    "trial {} of {} was answered in a session without sound (data entry, no "
                    "--live): nothing was heard, so there is nothing to re-render",
                    q.trial + 1, q.participant));
            throw ReplayError(fmt::format(
                "trial {} of {} was driven by a live sensor and no GRF recording is stored for "
                "it, so what was heard cannot be re-rendered exactly",
                q.trial + 1, q.participant));
        }
        StimulusRender render;
        render.stimulus = stimulus;
        render.seed = info.renderSeed;
        render.sampleRateHz = rate;
        render.blockSize = out.blockSize;
        render.grf = &grf;
        out.audio = renderStimulus(render);
        out.description =
            fmt::format("{} trial {} ({}{}{}): {:.1f} s from {}, render seed {}, block {}{}",
                        info.participant, info.trialIndex + 1, stimulus.surface,
                        stimulus.soundscape ? " + " : "", stimulus.soundscape.value_or(""),
                        double(out.audio.frames()) / rate, source, out.seed, out.blockSize,
                        recording && !q.blockSize && !live.blockSize
                            ? fmt::format(" (assumed: {}.meters.toml, which holds the live block "
                                          "size, is missing; if the live block differed, pass "
                                          "--block)",
                                          recording->string())
                            : std::string());
        return out;
    } catch (const ReplayError&) {
        throw;
    } catch (const std::exception& e) {
        throw ReplayError(e.what());
    }
}

} // namespace underfoot::wiring
