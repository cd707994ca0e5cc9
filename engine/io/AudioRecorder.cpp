// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/io/AudioRecorder.h"

#include "engine/io/AudioFile.h"

#include <boost/lockfree/spsc_queue.hpp>
#include <fmt/format.h>
#include <sndfile.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace underfoot::engine {

namespace {
constexpr int kScratchFrames = 1024; // push() interleaves in chunks of this many frames
}

struct AudioRecorder::Impl {
    explicit Impl(std::size_t capacity) : ring(capacity) {}
    boost::lockfree::spsc_queue<float> ring;
    std::vector<float> scratch; ///< producer's interleaving buffer
    SNDFILE* file = nullptr;
};

AudioRecorder::AudioRecorder(const std::string& path, int channels, double sampleRateHz,
                             double scale, double ringSeconds)
    : path_(path), channels_(channels), sampleRateHz_(sampleRateHz) {
    if (channels < 1 || channels > 64)
        throw std::invalid_argument(
            fmt::format("{}: a recording needs 1 to 64 channels, got {}", path, channels));
    if (!(sampleRateHz >= 1.0 && sampleRateHz <= 1e6))
        throw std::invalid_argument(
            fmt::format("{}: bad recording rate {} Hz", path, sampleRateHz));
    if (!(scale > 0.0) || !std::isfinite(scale))
        throw std::invalid_argument(fmt::format("{}: bad recording scale {}", path, scale));
    if (!(ringSeconds >= 0.1 && ringSeconds <= 600.0))
        throw std::invalid_argument(
            fmt::format("{}: ring of {} s; expected 0.1 to 600 s", path, ringSeconds));
    inverseScale_ = static_cast<float>(1.0 / scale);
    const auto frames = static_cast<std::size_t>(std::ceil(ringSeconds * sampleRateHz));
    impl_ = std::make_unique<Impl>(frames * static_cast<std::size_t>(channels) + 1);
    impl_->scratch.assign(static_cast<std::size_t>(kScratchFrames * channels), 0.0f);
    SF_INFO info{};
    info.samplerate = static_cast<int>(std::lround(sampleRateHz));
    info.channels = channels;
    info.format = SF_FORMAT_WAV | SF_FORMAT_FLOAT;
    impl_->file = sf_open(path.c_str(), SFM_WRITE, &info);
    if (!impl_->file)
        throw FileError(
            fmt::format("{}: cannot create the recording ({})", path, sf_strerror(nullptr)));
    // No PEAK chunk: its timestamp would make identical takes differ byte-wise.
    sf_command(impl_->file, SFC_SET_ADD_PEAK_CHUNK, nullptr, SF_FALSE);
    writer_ = std::thread([this] { writerLoop(); });
}

AudioRecorder::~AudioRecorder() {
    try {
        finish();
    } catch (...) {
        // finish() reports through error(); nothing may escape a destructor.
    }
}

bool AudioRecorder::push(const float* const* data, int n) noexcept {
    if (finished_ || n <= 0) return n <= 0;
    const auto ch = static_cast<std::size_t>(channels_);
    if (impl_->ring.write_available() < static_cast<std::size_t>(n) * ch) {
        dropped_.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_relaxed);
        return false;
    }
    float* s = impl_->scratch.data();
    for (int start = 0; start < n; start += kScratchFrames) {
        const int m = std::min(kScratchFrames, n - start);
        for (int i = 0; i < m; ++i)
            for (std::size_t c = 0; c < ch; ++c)
                s[static_cast<std::size_t>(i) * ch + c] = data[c][start + i] * inverseScale_;
        impl_->ring.push(s, static_cast<std::size_t>(m) * ch);
    }
    pushed_.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_release);
    return true;
}

void AudioRecorder::writerLoop() {
    const auto ch = static_cast<std::size_t>(channels_);
    std::vector<float> buf(static_cast<std::size_t>(8192) * ch);
    for (;;) {
        // Whether the producer asked us to stop is read BEFORE draining, so that everything
        // pushed before finish() is written.
        const bool stopping = stop_.load(std::memory_order_acquire);
        std::size_t avail = impl_->ring.read_available();
        while (avail >= ch) {
            const std::size_t take = std::min(buf.size(), avail - avail % ch);
            const std::size_t got = impl_->ring.pop(buf.data(), take);
            const auto frames = static_cast<sf_count_t>(got / ch);
            if (error_.empty() && sf_writef_float(impl_->file, buf.data(), frames) != frames)
                error_ = fmt::format("{}: write failed ({})", path_, sf_strerror(impl_->file));
            written_.fetch_add(static_cast<std::uint64_t>(frames), std::memory_order_release);
            avail = impl_->ring.read_available();
        }
        if (stopping) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
}

void AudioRecorder::finish() {
    if (finished_) return;
    finished_ = true;
    stop_.store(true, std::memory_order_release);
    if (writer_.joinable()) writer_.join();
    if (impl_ && impl_->file) {
        sf_write_sync(impl_->file);
        if (sf_close(impl_->file) != 0 && error_.empty())
            error_ = fmt::format("{}: closing the recording failed", path_);
        impl_->file = nullptr;
    }
}

} // namespace underfoot::engine
