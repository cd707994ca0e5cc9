// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/control/GrfFile.h"

#include "engine/dsp/ProcessSpec.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>

namespace underfoot::engine {

namespace {

constexpr double kClipLevel = 0.9999;       // |x| at or above this is digital full scale
constexpr int kClipRun = 3;                 // consecutive samples at full scale = clipped
constexpr double kNegativeTolerance = 0.02; // fraction of the channel's peak
constexpr double kMaxIrregularity = 0.25;   // allowed deviation of a time step from the median

std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
        s.remove_suffix(1);
    return s;
}

void validateOptions(const std::string& path, const GrfLoadOptions& o) {
    if (!(o.targetRateHz > 0) || !std::isfinite(o.targetRateHz))
        throw FileError(fmt::format("{}: target rate {} Hz must be a positive finite number", path,
                                    o.targetRateHz));
    if (!(o.fullScaleNewtons > 0) || !std::isfinite(o.fullScaleNewtons))
        throw FileError(fmt::format("{}: full scale {} N must be a positive finite number", path,
                                    o.fullScaleNewtons));
    if (!(o.bodyMassKg > 0) || !std::isfinite(o.bodyMassKg))
        throw FileError(fmt::format("{}: body mass {} kg must be a positive finite number", path,
                                    o.bodyMassKg));
}

// The documented limits on what a GRF file may claim (checked before resampling, whose output
// size and work follow duration x target rate).
void checkGrfLimits(const std::string& path, double rateHz, std::size_t frames,
                    const char* rateSource) {
    // A relative tolerance: a CSV's 1 / median step is 100 Hz only to within rounding.
    if (!(rateHz >= kMinGrfRateHz * (1 - 1e-6) && rateHz <= kMaxGrfRateHz * (1 + 1e-6)))
        throw FileError(fmt::format("{}: sample rate {:g} Hz ({}); expected a GRF sampled at {:g} "
                                    "to {:g} Hz",
                                    path, rateHz, rateSource, kMinGrfRateHz, kMaxGrfRateHz));
    const double seconds = static_cast<double>(frames) / rateHz;
    if (!(seconds <= kMaxGrfSeconds))
        throw FileError(fmt::format("{}: the GRF lasts {:.1f} s ({} samples at {:g} Hz); expected "
                                    "at most {:g} s (split a longer recording)",
                                    path, seconds, frames, rateHz, kMaxGrfSeconds));
}

// Resampling in stages of at most 256x (libsamplerate's limit), then clamping ringing below 0.
// The signal is extended at both ends by its first and last values (kGrfEdgeSeconds, at least
// kGrfEdgeSamples) and the extension is cut off again: the resampler starts from silence, so a
// file that starts or ends under load (a recording cut from a longer trial) would otherwise rise
// from 0 N over a few milliseconds, with the sinc's ringing (+14 % on a constant 600 N at
// 1 kHz), and the layers would hear a landing at the first sample and a strike at the last.
constexpr double kGrfEdgeSeconds = 0.05;
constexpr std::size_t kGrfEdgeSamples = 512;

GrfSignal resampleGrf(GrfSignal in, double targetRateHz) {
    if (in.sampleRateHz == targetRateHz) return in;
    AudioBuffer buf;
    buf.sampleRateHz = in.sampleRateHz;
    buf.channels = static_cast<int>(in.channels.size());
    const std::size_t n = in.frames(), ch = in.channels.size();
    const std::size_t edge =
        n == 0 ? 0
               : std::max(kGrfEdgeSamples,
                          static_cast<std::size_t>(std::ceil(kGrfEdgeSeconds * in.sampleRateHz)));
    buf.samples.resize((n + 2 * edge) * ch);
    for (std::size_t c = 0; c < ch; ++c)
        for (std::size_t i = 0; i < n + 2 * edge; ++i)
            buf.samples[i * ch + c] = in.channels[c][std::min(n - 1, i < edge ? 0 : i - edge)];
    while (buf.sampleRateHz != targetRateHz) {
        const double ratio = targetRateHz / buf.sampleRateHz;
        const double step = ratio > 200.0 ? 200.0 : (ratio < 1.0 / 200.0 ? 1.0 / 200.0 : ratio);
        const double next = (step == ratio) ? targetRateHz : buf.sampleRateHz * step;
        buf = resample(buf, next);
    }
    // Cut the extensions off (at the output rate; a fraction of an output sample of shift at
    // most when the rates are not in an integer ratio).
    const double ratio = targetRateHz / in.sampleRateHz;
    const auto skip = static_cast<std::size_t>(std::llround(static_cast<double>(edge) * ratio));
    const auto keep = static_cast<std::size_t>(std::llround(static_cast<double>(n) * ratio));
    GrfSignal out;
    out.sampleRateHz = targetRateHz;
    out.names = std::move(in.names);
    out.channels.assign(ch, std::vector<float>(keep));
    for (std::size_t c = 0; c < ch; ++c)
        for (std::size_t i = 0; i < keep && skip + i < buf.frames(); ++i)
            out.channels[c][i] = std::max(0.0f, buf.samples[(skip + i) * ch + c]);
    return out;
}

// (GrfTare) the unloaded plate's samples: below this fraction of the channel's peak
constexpr double kNearZeroFraction = 0.05;
constexpr double kTareSigmas = 4.0;

// Measured before the negative samples are set to 0 (they carry half of the noise).
std::vector<GrfTare> measureTares(const GrfSignal& grf, const GrfLoadOptions& o) {
    std::vector<GrfTare> tares;
    if (o.tare != GrfTareMode::Off)
        for (const auto& x : grf.channels) tares.push_back(measureGrfTare(x));
    return tares;
}

// The loaders' common end, once the negative samples are 0: the zeros taken off (Apply), the
// resampling, the tares reported.
GrfSignal finishGrf(GrfSignal grf, std::vector<GrfTare> tares, const GrfLoadOptions& o) {
    if (o.tare == GrfTareMode::Apply)
        for (std::size_t c = 0; c < tares.size(); ++c) {
            applyGrfTare(grf.channels[c], tares[c]);
            tares[c].applied = tares[c].subtractedN > 0.0;
        }
    GrfSignal out = resampleGrf(std::move(grf), o.targetRateHz);
    out.tare = std::move(tares);
    return out;
}

// Negative forces beyond noise are an error; small negative offsets are set to 0.
template <typename Where>
void checkNegative(const std::string& path, GrfSignal& grf, Where&& where) {
    for (std::size_t c = 0; c < grf.channels.size(); ++c) {
        auto& x = grf.channels[c];
        const float peak = x.empty() ? 0.0f : *std::max_element(x.begin(), x.end());
        const double tolerance = kNegativeTolerance * std::max(0.0f, peak);
        for (std::size_t i = 0; i < x.size(); ++i) {
            if (x[i] < -tolerance)
                throw FileError(fmt::format(
                    "{}: {}: negative force {:.3f} N in channel \"{}\"; expected a vertical ground "
                    "reaction force >= 0 (noise down to -{:.3f} N, 2 % of the channel's peak, is "
                    "tolerated)",
                    path, where(c, i), x[i], grf.names[c], tolerance));
            if (x[i] < 0) x[i] = 0;
        }
    }
}

GrfSignal loadAudioGrf(const std::string& path, const GrfLoadOptions& o) {
    const AudioBuffer audio = readAudioFile(path);
    checkGrfLimits(path, audio.sampleRateHz, audio.frames(), "from the file's header");
    const auto ch = static_cast<std::size_t>(audio.channels);
    GrfSignal grf;
    grf.sampleRateHz = audio.sampleRateHz;
    for (std::size_t c = 0; c < ch; ++c)
        grf.names.push_back(ch == 1   ? std::string("grf")
                            : ch == 2 ? std::string(c == 0 ? "left" : "right")
                                      : fmt::format("ch{}", c + 1));
    const std::size_t n = audio.frames();
    grf.channels.assign(ch, std::vector<float>(n));
    for (std::size_t c = 0; c < ch; ++c) {
        int run = 0;
        for (std::size_t i = 0; i < n; ++i) {
            const float v = audio.samples[i * ch + c];
            // Only integer files have a full scale to clip at: a float file (what the live
            // recorder writes) holds 1000 N as 1.0 like any other force.
            run = (!audio.floatingPoint && std::fabs(v) >= kClipLevel) ? run + 1 : 0;
            if (run == kClipRun && !o.allowClipped)
                throw FileError(fmt::format(
                    "{}: channel {} (\"{}\") is clipped at t = {:.6f} s (frame {}): {} or more "
                    "consecutive samples at full scale; expected a GRF recorded below full scale "
                    "(re-record with less gain, or set allowClipped to use it anyway)",
                    path, c + 1, grf.names[c],
                    static_cast<double>(i + 1 - kClipRun) / audio.sampleRateHz, i + 1 - kClipRun,
                    kClipRun));
            grf.channels[c][i] = static_cast<float>(v * o.fullScaleNewtons);
        }
    }
    const auto tares = measureTares(grf, o);
    checkNegative(path, grf, [&](std::size_t c, std::size_t i) {
        return fmt::format("channel {}, frame {} (t = {:.6f} s)", c + 1, i,
                           static_cast<double>(i) / audio.sampleRateHz);
    });
    return finishGrf(std::move(grf), tares, o);
}

GrfSignal loadCsvGrf(const std::string& path, const GrfLoadOptions& o) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
        throw FileError(fmt::format("{}: file not found (expected a GRF CSV file)", path));
    std::ifstream file(path, std::ios::binary);
    if (!file) throw FileError(fmt::format("{}: cannot open for reading", path));
    std::stringstream ss;
    ss << file.rdbuf();
    const std::string text = ss.str();

    std::vector<double> times;
    std::vector<std::vector<double>> values; // per channel
    std::vector<std::size_t> rowLines;       // line number of each row
    std::vector<double> scale;               // newtons per unit, per channel
    GrfSignal grf;
    bool haveHeader = false;
    std::size_t lineNo = 0, pos = 0;
    while (pos < text.size()) {
        const std::size_t eol = std::min(text.find('\n', pos), text.size());
        const std::string_view line(text.data() + pos, eol - pos);
        pos = eol + 1;
        ++lineNo;
        const std::string_view content = trim(line);
        if (content.empty() || content.front() == '#') continue;
        // Split into cells with their 1-based columns.
        std::vector<std::pair<std::string_view, std::size_t>> cells;
        std::size_t start = 0;
        while (true) {
            const std::size_t comma = std::min(line.find(',', start), line.size());
            cells.emplace_back(line.substr(start, comma - start), start + 1);
            if (comma >= line.size()) break;
            start = comma + 1;
        }
        if (!haveHeader) {
            if (trim(cells[0].first) != "time_s")
                throw FileError(fmt::format(
                    "{}:{}:{}: expected the header \"time_s,<name>[,<name>...]\" (first column "
                    "\"time_s\"), got \"{}\"",
                    path, lineNo, cells[0].second, trim(cells[0].first)));
            if (cells.size() < 2)
                throw FileError(fmt::format("{}:{}:{}: expected at least one force column after "
                                            "time_s",
                                            path, lineNo, line.size() + 1));
            for (std::size_t c = 1; c < cells.size(); ++c) {
                std::string name(trim(cells[c].first));
                if (name.empty())
                    throw FileError(fmt::format("{}:{}:{}: empty column name; expected a name "
                                                "such as left or heel_bw",
                                                path, lineNo, cells[c].second));
                double unit = 1.0;
                if (name.size() > 3 && name.compare(name.size() - 3, 3, "_bw") == 0) {
                    unit = o.bodyMassKg * kGravity;
                    name.resize(name.size() - 3);
                }
                if (std::find(grf.names.begin(), grf.names.end(), name) != grf.names.end())
                    throw FileError(fmt::format("{}:{}:{}: column \"{}\" appears twice", path,
                                                lineNo, cells[c].second, name));
                grf.names.push_back(name);
                scale.push_back(unit);
            }
            values.resize(grf.names.size());
            haveHeader = true;
            continue;
        }
        if (cells.size() != grf.names.size() + 1)
            throw FileError(fmt::format("{}:{}:{}: expected {} comma-separated values (time_s and "
                                        "{} force columns), found {}",
                                        path, lineNo, 1, grf.names.size() + 1, grf.names.size(),
                                        cells.size()));
        for (std::size_t c = 0; c < cells.size(); ++c) {
            const std::string_view cell = trim(cells[c].first);
            double v = 0;
            const auto [end, err] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
            const bool parsed =
                !cell.empty() && err == std::errc() && end == cell.data() + cell.size();
            const std::string what = c == 0 ? "a time in seconds" : "a force";
            if (!parsed) {
                // from_chars does not parse "nan"/"inf" spellings with signs in all cases; name
                // them.
                std::string lower(cell);
                std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char ch) {
                    return static_cast<char>(std::tolower(ch));
                });
                const bool nonFinite = lower.find("nan") != std::string::npos ||
                                       lower.find("inf") != std::string::npos;
                throw FileError(fmt::format(
                    "{}:{}:{}: {} \"{}\"; expected {} (a finite number)", path, lineNo,
                    cells[c].second, nonFinite ? "non-finite value" : "not a number", cell, what));
            }
            if (!std::isfinite(v))
                throw FileError(fmt::format("{}:{}:{}: non-finite value \"{}\"; expected {} (a "
                                            "finite number)",
                                            path, lineNo, cells[c].second, cell, what));
            if (c == 0) {
                if (!times.empty() && !(v > times.back()))
                    throw FileError(fmt::format(
                        "{}:{}:{}: time {} s is not after the previous row's {} s; expected "
                        "strictly increasing time",
                        path, lineNo, cells[c].second, v, times.back()));
                times.push_back(v);
            } else {
                values[c - 1].push_back(v * scale[c - 1]);
            }
        }
        rowLines.push_back(lineNo);
    }
    if (!haveHeader)
        throw FileError(fmt::format("{}: empty file; expected a header \"time_s,<name>...\" and "
                                    "rows of samples",
                                    path));
    if (times.size() < 2)
        throw FileError(fmt::format("{}: {} data row(s); expected at least two rows of samples",
                                    path, times.size()));
    // Roughly uniform time steps.
    std::vector<double> steps(times.size() - 1);
    for (std::size_t i = 1; i < times.size(); ++i) steps[i - 1] = times[i] - times[i - 1];
    std::vector<double> sorted = steps;
    std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
    const double dt = sorted[sorted.size() / 2];
    for (std::size_t i = 0; i < steps.size(); ++i)
        if (std::fabs(steps[i] - dt) > kMaxIrregularity * dt)
            throw FileError(fmt::format(
                "{}:{}:1: time step {} s differs from the median step {} s by more than 25 %; "
                "expected roughly uniform sampling (a gap or a duplicated block?)",
                path, rowLines[i + 1], steps[i], dt));
    // Interpolate onto the exact uniform grid of the median step, then resample.
    grf.sampleRateHz = 1.0 / dt;
    checkGrfLimits(path, grf.sampleRateHz, times.size(), "1 / the median time step");
    const auto n =
        static_cast<std::size_t>(std::floor((times.back() - times.front()) / dt + 1e-9)) + 1;
    grf.channels.assign(grf.names.size(), std::vector<float>(n));
    std::size_t j = 0;
    for (std::size_t k = 0; k < n; ++k) {
        const double t = times.front() + static_cast<double>(k) * dt;
        while (j + 2 < times.size() && times[j + 1] <= t) ++j;
        const double u = std::clamp((t - times[j]) / (times[j + 1] - times[j]), 0.0, 1.0);
        for (std::size_t c = 0; c < grf.names.size(); ++c)
            grf.channels[c][k] =
                static_cast<float>(values[c][j] + u * (values[c][j + 1] - values[c][j]));
    }
    // Negative check on the rows themselves so that the error names line and column.
    for (std::size_t c = 0; c < values.size(); ++c) {
        const double peak = *std::max_element(values[c].begin(), values[c].end());
        const double tolerance = kNegativeTolerance * std::max(0.0, peak);
        for (std::size_t i = 0; i < values[c].size(); ++i)
            if (values[c][i] < -tolerance)
                throw FileError(fmt::format(
                    "{}:{}: column \"{}\": negative force {:.3f} N; expected a vertical ground "
                    "reaction force >= 0 (noise down to -{:.3f} N, 2 % of the column's peak, is "
                    "tolerated)",
                    path, rowLines[i], grf.names[c], values[c][i], tolerance));
    }
    const auto tares = measureTares(grf, o);
    for (auto& x : grf.channels)
        for (float& v : x) v = std::max(0.0f, v);
    return finishGrf(std::move(grf), tares, o);
}

} // namespace

GrfTare measureGrfTare(const std::vector<float>& x) {
    GrfTare t;
    if (x.empty()) return t;
    const double peak = *std::max_element(x.begin(), x.end());
    if (!(peak > 0.0)) return t;
    const double limit = kNearZeroFraction * peak;
    std::vector<float> near; // (float as the channel: at most the channel's own size again)
    for (float v : x)
        if (std::fabs(v) < limit) near.push_back(v);
    t.samplesNearZero = near.size();
    if (near.size() < 50 || near.size() * 100 < x.size()) return t; // no swing phase to learn from
    auto median = [](std::vector<float>& v) {
        const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
        std::nth_element(v.begin(), mid, v.end());
        return static_cast<double>(*mid);
    };
    t.levelN = median(near);
    for (float& v : near) v = static_cast<float>(std::fabs(static_cast<double>(v) - t.levelN));
    t.noiseN = 1.4826 * median(near);
    const double zero = t.levelN + kTareSigmas * t.noiseN;
    // (a clean channel: 0; a level that is load, not the plate's zero: left as it is)
    if (zero > 0.0 && zero < limit) t.subtractedN = zero;
    return t;
}

void applyGrfTare(std::vector<float>& x, const GrfTare& t) {
    const auto z = static_cast<float>(t.subtractedN);
    for (float& v : x) v = std::max(0.0f, v - z);
}

std::string describeGrfTare(const GrfSignal& grf, const std::string& file) {
    std::string text;
    for (std::size_t c = 0; c < grf.tare.size() && c < grf.names.size(); ++c) {
        const GrfTare& t = grf.tare[c];
        if (t.applied)
            text += fmt::format(
                "{}: channel \"{}\": force-plate zero {:+.1f} N, noise {:.1f} N rms (from {} "
                "samples near 0 N): {:.1f} N taken off every sample, so that the unloaded plate's "
                "noise starts no contact in the air\n",
                file, grf.names[c], t.levelN, t.noiseN, t.samplesNearZero, t.subtractedN);
    }
    return text;
}

double GrfSignal::durationSeconds() const {
    return sampleRateHz > 0 ? static_cast<double>(frames()) / sampleRateHz : 0.0;
}

GrfSignal loadGrfFile(const std::string& path, const GrfLoadOptions& options) {
    validateOptions(path, options);
    if (lowerExtension(path) == ".csv") return loadCsvGrf(path, options);
    return loadAudioGrf(path, options);
}

void writeGrfWav(const std::string& path, const GrfSignal& grf, double fullScaleNewtons) {
    if (grf.channels.empty()) throw FileError(fmt::format("{}: GRF has no channel to write", path));
    if (!(fullScaleNewtons > 0) || !std::isfinite(fullScaleNewtons))
        throw FileError(
            fmt::format("{}: full scale {} N must be positive", path, fullScaleNewtons));
    AudioBuffer buf;
    buf.sampleRateHz = grf.sampleRateHz;
    buf.channels = static_cast<int>(grf.channels.size());
    const std::size_t n = grf.frames(), ch = grf.channels.size();
    buf.samples.resize(n * ch);
    for (std::size_t c = 0; c < ch; ++c) {
        if (grf.channels[c].size() != n)
            throw FileError(fmt::format("{}: GRF channels have different lengths", path));
        for (std::size_t i = 0; i < n; ++i)
            buf.samples[i * ch + c] = static_cast<float>(grf.channels[c][i] / fullScaleNewtons);
    }
    writeAudioFile(path, buf, SampleFormat::Float32);
}

} // namespace underfoot::engine
