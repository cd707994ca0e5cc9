// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/Compare.h"

#include "engine/render/AudioFeatures.h"
#include "engine/render/FootstepScene.h"
#include "engine/render/Renderer.h"
#include "engine/reverb/Convolver.h"
#include "engine/surfaces/Surface.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace underfoot::realism {

engine::AudioBuffer renderForComparison(const std::string& surface, const RenderSpec& spec) {
    const auto walker = engine::WalkerParameters::parse(spec.walker);
    const auto grf = engine::walkerGrf(walker, spec.seconds, spec.rateHz, spec.seed);
    engine::RenderOptions o;
    o.sampleRateHz = spec.rateHz;
    o.seed = spec.seed;
    o.tailSeconds = 1.0;
    return engine::renderSurface(surface, grf, o).audio;
}

std::optional<Example> renderExample(const std::string& id, const std::string& surface,
                                     const RenderSpec& spec, const AnalysisOptions& o) {
    const auto steps = describeSteps(renderForComparison(surface, spec), o);
    if (steps.empty()) return std::nullopt;
    return Example{id, "synthetic", materialOfSurface(id), fileFeatures(steps)};
}

namespace {
engine::AudioBuffer readRoomImpulse(const engine::ReverbSpec& room) {
    return engine::readAudioFile(engine::findImpulseResponse(room.impulseResponse));
}

// throughRoom() with the room's impulse response already read.
engine::AudioBuffer throughRoomWith(const engine::AudioBuffer& recording,
                                    const engine::AudioBuffer& ir, const engine::ReverbSpec& room) {
    constexpr int kBlock = 4096;
    engine::Convolver conv;
    conv.prepare(ir, recording.sampleRateHz, kBlock);
    const std::size_t frames = recording.frames() + conv.impulseLength();
    // The recording stands for the render's channel mean (what the analysis hears). The renderer
    // pans its two voices (feet) to +-panSpread with a constant-power law, so that mean holds
    // each voice x cos(panSpread pi / 4), while the room is fed the voices' plain sum: the room's
    // input is the recording / cos(panSpread pi / 4) (0.24 dB with the default spread 0.3).
    const double panLaw = std::cos(engine::SceneOptions{}.panSpread * std::numbers::pi / 4);
    const double dry = std::pow(10.0, room.dryDb / 20.0),
                 wet = std::pow(10.0, room.wetDb / 20.0) / panLaw;
    std::vector<float> mono(frames, 0.0f), wetL(frames), wetR(frames);
    for (std::size_t f = 0; f < recording.frames(); ++f) {
        double s = 0;
        for (int c = 0; c < recording.channels; ++c) s += recording.at(f, c);
        mono[f] = static_cast<float>(s / std::max(1, recording.channels));
    }
    for (std::size_t at = 0; at < frames; at += kBlock) {
        const int n = int(std::min<std::size_t>(kBlock, frames - at));
        conv.process(mono.data() + at, wetL.data() + at, wetR.data() + at, n);
    }
    engine::AudioBuffer out;
    out.sampleRateHz = recording.sampleRateHz;
    out.channels = 2;
    out.samples.resize(2 * frames);
    for (std::size_t f = 0; f < frames; ++f) {
        const double d = dry * mono[f];
        out.samples[2 * f] = static_cast<float>(d + wet * wetL[f]);
        out.samples[2 * f + 1] = static_cast<float>(d + wet * wetR[f]);
    }
    return out;
}
} // namespace

engine::AudioBuffer throughRoom(const engine::AudioBuffer& recording,
                                const engine::ReverbSpec& room) {
    return throughRoomWith(recording, readRoomImpulse(room), room);
}

std::vector<StepDescriptors> describeRecordings(const std::vector<Recording>& recordings,
                                                const AnalysisOptions& options,
                                                const std::optional<engine::ReverbSpec>& room) {
    const auto ir = room ? readRoomImpulse(*room) : engine::AudioBuffer{};
    std::vector<StepDescriptors> steps;
    for (const auto& r : recordings) {
        const auto s =
            room ? describeSteps(throughRoomWith(engine::readAudioFile(r.path), ir, *room), options)
                 : describeFile(r.path, options);
        steps.insert(steps.end(), s.begin(), s.end());
    }
    return steps;
}

std::optional<engine::ReverbSpec> roomOfSurface(const std::string& surface) {
    return engine::Surface::loadById(surface)->info().reverb;
}

namespace {
// The step whose descriptors are nearest the medians (a typical step), as samples.
std::vector<float> typicalStep(const engine::AudioBuffer& audio, const AnalysisOptions& o) {
    const auto x = analysisSignal(audio, o);
    const auto spans = segmentSteps(x, o.analysisRateHz, o);
    if (spans.empty()) return {};
    const auto& s = spans[spans.size() / 2];
    return std::vector<float>(x.begin() + long(s.begin), x.begin() + long(s.end));
}
} // namespace

SurfaceComparison compareAudio(const std::string& surface, const engine::AudioBuffer& synthetic,
                               const std::vector<Recording>& real,
                               const std::optional<engine::ReverbSpec>& room) {
    SurfaceComparison c;
    c.surface = surface;
    c.material = materialOfSurface(surface);
    c.options.maxHz = sharedMaxHz(real, synthetic.sampleRateHz);
    c.room = room;
    const auto ir = room ? readRoomImpulse(*room) : engine::AudioBuffer{};
    for (const auto& r : real) {
        const auto audio = room ? throughRoomWith(engine::readAudioFile(r.path), ir, *room)
                                : engine::readAudioFile(r.path);
        auto steps = describeSteps(audio, c.options);
        c.realSteps.insert(c.realSteps.end(), steps.begin(), steps.end());
        c.realFiles.push_back(r.file);
        if (c.realExample.empty()) c.realExample = typicalStep(audio, c.options);
    }
    if (c.realSteps.empty())
        throw std::runtime_error("no footstep found in the recordings (all silent?)");
    c.syntheticSteps = describeSteps(synthetic, c.options);
    if (c.syntheticSteps.empty())
        throw std::runtime_error(fmt::format("{}: the render holds no footstep", surface));
    c.syntheticExample = typicalStep(synthetic, c.options);
    c.comparison = compareSteps(c.syntheticSteps, c.realSteps);
    return c;
}

SurfaceComparison compareSurface(const std::string& surface, const std::vector<Recording>& real,
                                 const RenderSpec& spec,
                                 const std::optional<engine::ReverbSpec>& room) {
    return compareAudio(surface, renderForComparison(surface, spec), real, room);
}

namespace {
std::vector<double> medianBands(const std::vector<StepDescriptors>& steps) {
    std::vector<double> out;
    if (steps.empty()) return out;
    for (std::size_t b = 0; b < steps.front().thirdOctaveDb.size(); ++b) {
        std::vector<double> v;
        for (const auto& s : steps) v.push_back(s.thirdOctaveDb[b]);
        out.push_back(quantile(v, 0.5));
    }
    return out;
}
std::string esc(const std::string& s) {
    std::string o;
    for (char ch : s) {
        if (ch == '<')
            o += "&lt;";
        else if (ch == '>')
            o += "&gt;";
        else if (ch == '&')
            o += "&amp;";
        else
            o += ch;
    }
    return o;
}
} // namespace

std::string bandPlotSvg(const SurfaceComparison& c) {
    const auto centres = thirdOctaveCentres(c.options.maxHz);
    const auto syn = medianBands(c.syntheticSteps), rea = medianBands(c.realSteps);
    const double w = 560, h = 300, l = 50, r = 10, t = 30, b = 40;
    const double lo = -50, hi = 0;
    const double f0 = std::log2(40.0), f1 = std::log2(c.options.maxHz);
    auto X = [&](double f) { return l + (std::log2(f) - f0) / (f1 - f0) * (w - l - r); };
    auto Y = [&](double v) { return t + (hi - std::clamp(v, lo, hi)) / (hi - lo) * (h - t - b); };
    std::string s = fmt::format(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" "
        "font-family=\"sans-serif\" "
        "font-size=\"11\"><rect width=\"100%\" height=\"100%\" fill=\"white\"/>"
        "<text x=\"{}\" y=\"18\" font-size=\"13\">{}: third-octave bands re total (median step), "
        "real vs synthetic</text>",
        w, h, l, esc(c.surface));
    for (double v = lo; v <= hi; v += 10)
        s += fmt::format("<line x1=\"{}\" x2=\"{}\" y1=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#ddd\"/>"
                         "<text x=\"5\" y=\"{:.1f}\">{} dB</text>",
                         l, w - r, Y(v), Y(v), Y(v) + 4, v);
    for (double f : {50.0, 100.0, 250.0, 500.0, 1000.0, 2000.0, 4000.0, 8000.0, 16000.0})
        if (f <= c.options.maxHz)
            s += fmt::format(
                "<line x1=\"{:.1f}\" x2=\"{:.1f}\" y1=\"{}\" y2=\"{}\" stroke=\"#eee\"/>"
                "<text x=\"{:.1f}\" y=\"{}\" text-anchor=\"middle\">{}</text>",
                X(f), X(f), t, h - b, X(f), h - b + 14,
                f >= 1000 ? fmt::format("{:g}k", f / 1000) : fmt::format("{:g}", f));
    auto line = [&](const std::vector<double>& v, const char* colour, const char* label,
                    double ly) {
        std::string pts;
        for (std::size_t i = 0; i < v.size() && i < centres.size(); ++i)
            pts += fmt::format("{:.1f},{:.1f} ", X(centres[i]), Y(v[i]));
        return fmt::format(
            "<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"2\" points=\"{}\"/>"
            "<line x1=\"{}\" x2=\"{}\" y1=\"{}\" y2=\"{}\" stroke=\"{}\" stroke-width=\"2\"/>"
            "<text x=\"{}\" y=\"{}\">{}</text>",
            colour, pts, w - 150, w - 130, ly, ly, colour, w - 125, ly + 4, label);
    };
    s += line(rea, "#1f77b4", "recorded", t + 10);
    s += line(syn, "#d62728", "synthetic", t + 26);
    s += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">Hz</text></svg>\n", w / 2,
                     h - 8);
    return s;
}

std::string spectrogramSvg(const std::vector<float>& step, double fs, double maxHz,
                           const std::string& title) {
    const double w = 300, h = 220, l = 40, t = 24, b = 20;
    std::string s =
        fmt::format("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" "
                    "font-family=\"sans-serif\" "
                    "font-size=\"11\"><rect width=\"100%\" height=\"100%\" fill=\"white\"/>"
                    "<text x=\"{}\" y=\"16\" font-size=\"12\">{}</text>",
                    w, h, l, esc(title));
    engine::AudioBuffer a;
    a.sampleRateHz = fs;
    a.channels = 1;
    a.samples = step;
    a.samples.resize(std::max<std::size_t>(step.size(), 2048), 0.0f);
    const int n = 512, hop = 128;
    const auto spec = engine::spectrogramDb(a, n, hop);
    if (spec.empty()) return s + "</svg>\n";
    const int rows = 48;
    const double f0 = std::log2(50.0), f1 = std::log2(maxHz);
    float top = -300;
    for (const auto& fr : spec)
        for (float v : fr) top = std::max(top, v);
    const double cw = (w - l - 5) / double(spec.size()), rh = (h - t - b) / rows;
    for (std::size_t fIdx = 0; fIdx < spec.size(); ++fIdx)
        for (int rIdx = 0; rIdx < rows; ++rIdx) {
            const double fa = std::exp2(f0 + (f1 - f0) * rIdx / rows);
            const double fb = std::exp2(f0 + (f1 - f0) * (rIdx + 1) / rows);
            auto ka = static_cast<std::size_t>(fa / fs * n),
                 kb = static_cast<std::size_t>(fb / fs * n);
            kb = std::min(std::max(kb, ka + 1), spec[fIdx].size());
            float m = -300;
            for (std::size_t k = ka; k < kb; ++k) m = std::max(m, spec[fIdx][k]);
            const double level = std::clamp((double(m) - (double(top) - 60.0)) / 60.0, 0.0, 1.0);
            const int g = static_cast<int>(255 * (1 - level));
            s += fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.2f}\" height=\"{:.2f}\" "
                             "fill=\"rgb({},{},{})\"/>",
                             l + cw * double(fIdx), h - b - rh * (rIdx + 1), cw + 0.3, rh + 0.3, g,
                             g, std::min(255, g + 40));
        }
    for (double f : {100.0, 1000.0, 10000.0})
        if (f < maxHz) {
            const double y = h - b - (std::log2(f) - f0) / (f1 - f0) * (h - t - b);
            s += fmt::format("<text x=\"2\" y=\"{:.1f}\">{}</text>", y + 4,
                             f >= 1000 ? fmt::format("{:g}k", f / 1000) : fmt::format("{:g}", f));
        }
    s += fmt::format("<text x=\"{}\" y=\"{}\">{:.0f} ms, 60 dB range</text></svg>\n", l, h - 5,
                     1000.0 * double(step.size()) / fs);
    return s;
}

std::string descriptorTableHtml(const SurfaceComparison& c) {
    std::string s = "<table><tr><th>descriptor</th><th>unit</th><th>synthetic (median)</th>"
                    "<th>recorded median</th><th>recorded IQR</th><th>z</th></tr>\n";
    for (int d = 0; d < kDescriptorCount; ++d) {
        const auto& x = c.comparison.d[static_cast<std::size_t>(d)];
        const auto& info = descriptorInfo(d);
        s += fmt::format("<tr><td title=\"{}\">{}</td><td>{}</td><td>{:.4g}</td><td>{:.4g}</td>"
                         "<td>{:.4g} – {:.4g}</td><td{}>{:.2f}</td></tr>\n",
                         info.name, info.key, info.unit, x.synthetic, x.realMedian, x.realQ1,
                         x.realQ3, x.z > 2 ? " class=\"far\"" : "", x.z);
    }
    s += fmt::format("<tr><th colspan=\"5\">distance (mean z)</th><th>{:.2f}</th></tr></table>\n",
                     c.comparison.distance);
    return s;
}

std::string descriptorTableText(const SurfaceComparison& c) {
    std::string s = fmt::format("{:<18} {:>5} {:>12} {:>12} {:>25} {:>7}\n", "descriptor", "unit",
                                "synthetic", "real median", "real IQR", "z");
    for (int d = 0; d < kDescriptorCount; ++d) {
        const auto& x = c.comparison.d[static_cast<std::size_t>(d)];
        const auto& info = descriptorInfo(d);
        s += fmt::format("{:<18} {:>5} {:>12.4g} {:>12.4g} {:>12.4g} – {:<10.4g} {:>7.2f}\n",
                         info.key, info.unit, x.synthetic, x.realMedian, x.realQ1, x.realQ3, x.z);
    }
    s += fmt::format("distance (mean robust z over {} descriptors; {} synthetic steps, {} recorded "
                     "steps, band {:.0f}-{:.0f} Hz): {:.2f}\n",
                     int(kDescriptorCount), c.comparison.syntheticSteps, c.comparison.realSteps,
                     c.options.minHz, c.options.maxHz, c.comparison.distance);
    return s;
}

} // namespace underfoot::realism
