// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/scene/WadingNode.h"

#include "engine/dsp/Denormals.h"
#include "engine/io/sensors/OscGyroReceiver.h"
#include "engine/io/sensors/SensorClock.h"
#include "engine/wading/Gait.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>

namespace underfoot::engine {

// ---------------------------------------------------------------------------------------------
// Live gyroscopes

LiveGyroGaitSource::LiveGyroGaitSource(std::shared_ptr<OscGyroReceiver> receiver)
    : receiver_(std::move(receiver)) {
    if (!receiver_) throw std::invalid_argument("LiveGyroGaitSource: no OSC gyroscope receiver");
}

void LiveGyroGaitSource::prepare(const ProcessSpec& spec) {
    rateHz_ = spec.sampleRateHz;
}

void LiveGyroGaitSource::reset(std::uint64_t) noexcept {
    assembler_.reset();
    sinceFrame_ = 0;
    silentMode_ = false;
    rejectedBefore_ = 0;
    popped_ = 0;
    rejected_ = 0;
    silent_ = 0;
}

int LiveGyroGaitSource::pull(int n, TimedGaitFrame* frames, int capacity) noexcept {
    int count = 0;
    GyroSample sample;
    GaitFrame frame;
    // Everything that arrived since the last block; frames become effective at this block's
    // first sample. A bounded loop: a flood cannot hold the audio thread (the rest waits).
    for (int k = 0; k < 4096 && receiver_->popSample(sample); ++k) {
        popped_.fetch_add(1, std::memory_order_relaxed);
        if (assembler_.push(sample, frame)) {
            silentMode_ = false;
            sinceFrame_ = 0;
            if (count < capacity) frames[count++] = {0, frame};
        }
    }
    rejected_.store(rejectedBefore_ + assembler_.rejectedSamples(), std::memory_order_relaxed);
    // Silence: after kGyroSilenceSeconds without a frame, stand still (a zero frame every
    // period, at the sample where it is due, stamped on the sensor clock) and let the next real
    // sample start afresh.
    const auto silence = static_cast<std::int64_t>(std::llround(kGyroSilenceSeconds * rateHz_));
    const auto period = static_cast<std::int64_t>(std::llround(rateHz_ / kGaitFrameRateHz));
    if (count == 0) {
        const double nowS = sensorClockSeconds();
        while (count < capacity) {
            const std::int64_t limit = silentMode_ ? period : silence;
            const std::int64_t due = std::max<std::int64_t>(0, limit - sinceFrame_);
            if (due >= n) break;
            if (!silentMode_) {
                rejectedBefore_ += assembler_.rejectedSamples();
                assembler_.reset(); // the limbs' held readings are stale now
                silentMode_ = true;
            }
            GaitFrame still{};
            still.timeS = nowS + static_cast<double>(due) / rateHz_;
            frames[count++] = {static_cast<int>(due), still};
            silent_.fetch_add(1, std::memory_order_relaxed);
            sinceFrame_ = -due; // counts from the made-up frame
        }
    }
    sinceFrame_ += n;
    return count;
}

// ---------------------------------------------------------------------------------------------
// Virtual gait

VirtualGaitSource::VirtualGaitSource(VirtualGaitParameters parameters, double loopSeconds)
    : parameters_(parameters), loopSeconds_(loopSeconds) {
    parameters_.validate();
    if (!std::isfinite(loopSeconds_) || loopSeconds_ < 1.0 || loopSeconds_ > 3600.0)
        throw std::invalid_argument(
            fmt::format("VirtualGaitSource: loop of {} s; expected [1, 3600] s", loopSeconds));
}

void VirtualGaitSource::prepare(const ProcessSpec& spec) {
    rateHz_ = spec.sampleRateHz;
    gait_ = virtualGait(parameters_, loopSeconds_, seed_);
    if (gait_.empty()) throw std::invalid_argument("VirtualGaitSource: no gait frames");
}

void VirtualGaitSource::reset(std::uint64_t seed) noexcept {
    // The gait of a new seed is computed in prepare(); reset only rewinds (the seed given at
    // prepare time, i.e. the node's first reset before prepare, selects the gait).
    seed_ = seed;
    sample_ = 0;
    nextFrame_ = 0;
}

int VirtualGaitSource::pull(int n, TimedGaitFrame* frames, int capacity) noexcept {
    int count = 0;
    const auto size = static_cast<std::int64_t>(gait_.size());
    while (count < capacity && size > 0) {
        // Frame k (at k / 100 s) takes effect at the sample where it is due, as renderWading.
        const auto at = static_cast<std::int64_t>(
            std::llround(static_cast<double>(nextFrame_) / kGaitFrameRateHz * rateHz_));
        if (at >= sample_ + n) break;
        GaitFrame f = gait_[static_cast<std::size_t>(nextFrame_ % size)];
        f.timeS = static_cast<double>(nextFrame_) / kGaitFrameRateHz;
        frames[count++] = {static_cast<int>(std::max<std::int64_t>(0, at - sample_)), f};
        ++nextFrame_;
    }
    sample_ += n;
    return count;
}

std::string VirtualGaitSource::name() const {
    if (parameters_.cadenceStepsPerMin <= 0) return "virtual gait, standing";
    return fmt::format("virtual gait {:g} steps/min", parameters_.cadenceStepsPerMin);
}

// ---------------------------------------------------------------------------------------------
// Node

WadingNode::WadingNode(const WadingOptions& options, std::unique_ptr<GaitSource> source,
                       std::size_t recordCapacityFrames)
    : options_(options), source_(std::move(source)) {
    if (!source_) throw std::invalid_argument("WadingNode: no gait source");
    validateWadingOptions(options_);
    scene_.configure(loadWadingPreset(options_.depth), parseWadingAlgorithm(options_.algorithm),
                     parseGyroFilter(options_.filter));
    record_.resize(recordCapacityFrames);
    recordSample_.resize(recordCapacityFrames);
    frames_.resize(kMaxFramesPerBlock);
}

void WadingNode::prepare(const ProcessSpec& spec) {
    source_->reset(options_.seed); // selects the virtual gait's seed before it is computed
    source_->prepare(spec);
    scene_.prepare(spec);
}

void WadingNode::reset(std::uint64_t seed) noexcept {
    source_->reset(seed);
    scene_.reset(seed);
    recorded_ = 0;
    overflow_ = 0;
    applied_ = 0;
    samples_ = 0;
}

void WadingNode::process(float* left, float* right, int n) noexcept {
    const int count = source_->pull(n, frames_.data(), kMaxFramesPerBlock);
    if (count > 0) {
        std::size_t r = recorded_.load(std::memory_order_relaxed);
        const std::int64_t blockStart = samples_.load(std::memory_order_relaxed);
        for (int k = 0; k < count; ++k) {
            if (r < record_.size()) {
                const auto& f = frames_[static_cast<std::size_t>(k)];
                recordSample_[r] = blockStart + f.offset;
                record_[r++] = f.frame;
            } else
                overflow_.fetch_add(1, std::memory_order_relaxed);
        }
        recorded_.store(r, std::memory_order_release);
        applied_.fetch_add(static_cast<std::uint64_t>(count), std::memory_order_relaxed);
    }
    scene_.process(frames_.data(), count, left, right, n);
    samples_.fetch_add(n, std::memory_order_release);
}

GaitArrivals WadingNode::arrivals() const {
    GaitArrivals out;
    out.samples = samples_.load(std::memory_order_acquire);
    const std::size_t n = recorded_.load(std::memory_order_acquire);
    out.frames.reserve(n);
    for (std::size_t k = 0; k < n; ++k) out.frames.push_back({recordSample_[k], record_[k]});
    return out;
}

void WadingNode::writeArrivals(const std::string& path) const {
    if (overflow_.load() > 0)
        throw GaitFileError(fmt::format("{}: {} gait frames did not fit the recording, so the "
                                        "arrivals cannot reproduce the run",
                                        path, overflow_.load()));
    writeGaitArrivals(path, arrivals());
}

std::vector<GaitFrame> WadingNode::recording() const {
    const std::size_t n = recorded_.load(std::memory_order_acquire);
    std::vector<GaitFrame> out(record_.begin(), record_.begin() + static_cast<std::ptrdiff_t>(n));
    if (out.empty()) return out;
    // Relative times, strictly increasing at the CSV's 0.1 ms resolution.
    const double t0 = out.front().timeS;
    double last = -1.0;
    for (auto& f : out) {
        double t = std::round((f.timeS - t0) * 1e4) / 1e4;
        if (t <= last) t = last + 1e-4;
        f.timeS = last = t;
    }
    return out;
}

void WadingNode::writeRecording(const std::string& path) const {
    writeGaitCsv(path, recording());
}

std::string WadingNode::summary() const {
    return fmt::format("water ({}, {}, {}), {}", options_.depth, options_.algorithm,
                       options_.filter, source_->name());
}

// ---------------------------------------------------------------------------------------------
// Gait arrivals: the recording that reproduces a live node exactly

namespace {

constexpr const char* kArrivalsHeader =
    "sample,time_s,left_thigh_dps,right_thigh_dps,left_shank_dps,right_shank_dps";
constexpr std::size_t kMaxArrivals = 100'000'000;
constexpr double kMaxArrivalGapS = 30.0; ///< longest stretch of a replayed run without a frame

} // namespace

void writeGaitArrivals(const std::string& path, const GaitArrivals& a) {
    std::ofstream out(path, std::ios::binary);
    if (!out) throw GaitFileError(fmt::format("{}: cannot write the gait arrivals file", path));
    out << "# Underfoot gait arrivals: each gait frame with the sample (from the wading node's "
           "start) at which the live node applied it; angular velocities in deg/s\n";
    out << "# samples = " << a.samples << "\n";
    out << kArrivalsHeader << "\n";
    std::int64_t last = 0;
    for (const auto& f : a.frames) {
        if (f.sample < last || f.sample >= a.samples)
            throw GaitFileError(fmt::format("{}: refusing to write a frame at sample {} (after "
                                            "{}, in a run of {} samples)",
                                            path, f.sample, last, a.samples));
        last = f.sample;
        if (!std::isfinite(f.frame.timeS))
            throw GaitFileError(fmt::format("{}: refusing to write a non-finite time at sample {}",
                                            path, f.sample));
        for (double v : f.frame.angularVelocityDps)
            if (!std::isfinite(v))
                throw GaitFileError(fmt::format("{}: refusing to write a non-finite angular "
                                                "velocity at sample {}",
                                                path, f.sample));
        const auto& w = f.frame.angularVelocityDps;
        out << fmt::format("{},{},{},{},{},{}\n", f.sample, f.frame.timeS, w[0], w[1], w[2], w[3]);
    }
    if (!out) throw GaitFileError(fmt::format("{}: write failed", path));
}

GaitArrivals parseGaitArrivals(const std::string& text, const std::string& file) {
    GaitArrivals a;
    bool haveSamples = false, haveHeader = false;
    std::size_t lineNo = 0, pos = 0;
    const auto fail = [&](const std::string& what) {
        return GaitFileError(fmt::format("{}:{}: {}", file, lineNo, what));
    };
    const auto number = [&](std::string_view field, double& v) {
        const auto r = std::from_chars(field.data(), field.data() + field.size(), v);
        return r.ec == std::errc{} && r.ptr == field.data() + field.size() && std::isfinite(v);
    };
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        std::string_view line(text.data() + pos, end - pos);
        pos = end + 1;
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        if (line.empty()) continue;
        if (line.front() == '#') {
            constexpr std::string_view key = "# samples = ";
            if (line.substr(0, key.size()) == key) {
                // One run length, before the frames it bounds (a later one would leave frames
                // already read outside the run; found by fuzz_gait_arrivals).
                if (haveSamples)
                    throw fail(fmt::format("`{}`: a second `# samples = ` line; expected one, "
                                           "before the header",
                                           line));
                const auto v = line.substr(key.size());
                const auto r = std::from_chars(v.data(), v.data() + v.size(), a.samples);
                if (r.ec != std::errc{} || r.ptr != v.data() + v.size() || a.samples <= 0)
                    throw fail(fmt::format("`{}`: expected `# samples = ` and a positive whole "
                                           "number of samples",
                                           line));
                haveSamples = true;
            }
            continue;
        }
        if (!haveHeader) {
            if (line != kArrivalsHeader)
                throw fail(fmt::format("header `{}`: expected `{}`", line, kArrivalsHeader));
            if (!haveSamples)
                throw fail("no `# samples = N` line before the header (the length of the run)");
            haveHeader = true;
            continue;
        }
        if (a.frames.size() >= kMaxArrivals)
            throw fail(fmt::format("more than {} frames", kMaxArrivals));
        std::string_view fields[6];
        std::size_t count = 0, from = 0;
        while (count < 6) {
            const std::size_t comma = line.find(',', from);
            fields[count++] =
                line.substr(from, comma == std::string_view::npos ? line.npos : comma - from);
            if (comma == std::string_view::npos) break;
            from = comma + 1;
            if (count == 6)
                throw fail("more than 6 fields: expected sample, time and 4 angular velocities");
        }
        if (count != 6)
            throw fail(
                fmt::format("{} fields: expected sample, time and 4 angular velocities", count));
        GaitArrival f;
        const auto r =
            std::from_chars(fields[0].data(), fields[0].data() + fields[0].size(), f.sample);
        if (r.ec != std::errc{} || r.ptr != fields[0].data() + fields[0].size())
            throw fail(fmt::format("sample `{}`: expected a whole number", fields[0]));
        const std::int64_t last = a.frames.empty() ? 0 : a.frames.back().sample;
        if (f.sample < last || f.sample >= a.samples)
            throw fail(fmt::format("sample {}: expected {} to {} (in order, within the run of "
                                   "{} samples)",
                                   f.sample, last, a.samples - 1, a.samples));
        if (!number(fields[1], f.frame.timeS))
            throw fail(fmt::format("time `{}`: expected a finite number of seconds", fields[1]));
        for (std::size_t l = 0; l < 4; ++l)
            if (!number(fields[2 + l], f.frame.angularVelocityDps[l]))
                throw fail(fmt::format("angular velocity `{}`: expected a finite number of deg/s",
                                       fields[2 + l]));
        a.frames.push_back(f);
    }
    if (!haveHeader)
        throw GaitFileError(fmt::format("{}: no header line `{}`", file, kArrivalsHeader));
    return a;
}

GaitArrivals readGaitArrivals(const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    if (!file) throw GaitFileError(fmt::format("{}: cannot open the gait arrivals file", path));
    std::ostringstream ss;
    ss << file.rdbuf();
    return parseGaitArrivals(ss.str(), path);
}

RecordedGaitSource::RecordedGaitSource(std::vector<GaitArrival> frames)
    : frames_(std::move(frames)) {}

void RecordedGaitSource::reset(std::uint64_t) noexcept {
    next_ = 0;
    sample_ = 0;
}

int RecordedGaitSource::pull(int n, TimedGaitFrame* frames, int capacity) noexcept {
    int count = 0;
    while (count < capacity && next_ < frames_.size() && frames_[next_].sample < sample_ + n) {
        const auto& f = frames_[next_++];
        frames[count++] = {static_cast<int>(std::max<std::int64_t>(0, f.sample - sample_)),
                           f.frame};
    }
    sample_ += n;
    return count;
}

AudioBuffer renderWadingArrivals(const WadingOptions& options, const GaitArrivals& arrivals,
                                 int blockSize, LimiterReport* report) {
    if (blockSize < 1 || blockSize > 65536)
        throw WadingOptionError(fmt::format("block size {}: expected 1 to 65536", blockSize));
    if (arrivals.samples <= 0 ||
        arrivals.samples > static_cast<std::int64_t>(24 * 3600 * options.sampleRateHz))
        throw WadingOptionError(
            fmt::format("a run of {} samples: expected 1 sample to 24 hours", arrivals.samples));
    // The run's length is a number read from the file: it may only extend kMaxGapS past the
    // frames around it, so the memory it asks for is bounded by what the file holds (a live
    // node receives gyroscope frames every ~10 ms; a gap of half a minute is a lost sensor).
    const auto maxGap = static_cast<std::int64_t>(kMaxArrivalGapS * options.sampleRateHz);
    std::int64_t previous = 0;
    for (const auto& f : arrivals.frames) {
        if (f.sample - previous > maxGap)
            throw WadingOptionError(fmt::format(
                "gait arrivals: {:.1f} s without a frame (sample {} to {}): expected at most "
                "{:.0f} s between frames; such a gap is a lost gyroscope, whose trial cannot be "
                "replayed from its arrivals",
                double(f.sample - previous) / options.sampleRateHz, previous, f.sample,
                kMaxArrivalGapS));
        previous = f.sample;
    }
    if (arrivals.samples - previous > maxGap)
        throw WadingOptionError(fmt::format(
            "gait arrivals: a run of {} samples whose last frame is at sample {}: expected the "
            "run to end at most {:.0f} s after its last frame",
            arrivals.samples, previous, kMaxArrivalGapS));
    WadingNode node(options, std::make_unique<RecordedGaitSource>(arrivals.frames), 0);
    node.prepare({options.sampleRateHz, blockSize});
    node.reset(options.seed);
    const auto total = static_cast<std::size_t>(arrivals.samples);
    AudioBuffer out;
    out.sampleRateHz = options.sampleRateHz;
    out.channels = 2;
    out.samples.assign(total * 2, 0.0f);
    StereoSafetyLimiter limiter; // the output stage of every offline render
    limiter.prepare(options.sampleRateHz);
    std::vector<float> l(static_cast<std::size_t>(blockSize)), r(l.size());
    ScopedFlushDenormals ftz; // as the live scene around the node
    for (std::size_t start = 0; start < total; start += l.size()) {
        const int n = static_cast<int>(std::min(l.size(), total - start));
        node.process(l.data(), r.data(), n);
        limiter.process(l.data(), r.data(), n);
        for (int i = 0; i < n; ++i) {
            const auto k = static_cast<std::size_t>(i);
            out.samples[2 * (start + k)] = l[k];
            out.samples[2 * (start + k) + 1] = r[k];
        }
    }
    if (report) *report = limiter.report();
    return out;
}

} // namespace underfoot::engine
