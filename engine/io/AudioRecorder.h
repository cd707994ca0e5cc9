// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Real-time recording: the audio thread pushes planar blocks into a lock-free single-producer /
/// single-consumer ring (Boost.Lockfree); a writer thread drains it into a float WAV file
/// (libsndfile, streamed: memory does not grow with the take).
///
/// For GRF recordings (the control signal of a live trial) the samples are newtons / scale with
/// scale = 1000 N (engine/control/GrfFile.h convention), so `loadGrfFile` and `underfoot replay`
/// read them back; for audio recordings the scale is 1.
///
/// push() never allocates, locks or blocks: when the ring is full (the writer fell behind by
/// more than the ring's length) the block is dropped and counted; a take with dropped frames is
/// incomplete, which droppedFrames() reports.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

namespace underfoot::engine {

class AudioRecorder {
  public:
    /// Opens `path` for writing (float WAV, `channels` channels at `sampleRateHz`) and starts the
    /// writer thread. `ringSeconds` of audio fit in the ring. Throws FileError when the file
    /// cannot be created, std::invalid_argument for bad arguments.
    AudioRecorder(const std::string& path, int channels, double sampleRateHz, double scale = 1.0,
                  double ringSeconds = 4.0);
    /// Finishes (see finish()).
    ~AudioRecorder();
    AudioRecorder(const AudioRecorder&) = delete;
    AudioRecorder& operator=(const AudioRecorder&) = delete;

    /// Audio thread: appends n frames, channel c from data[c] (divided by the scale).
    /// Returns false (and counts the frames as dropped) when the ring has no room.
    bool push(const float* const* data, int n) noexcept;
    /// Main thread: waits until everything pushed so far is written, stops the writer and closes
    /// the file (idempotent). Call after the producer stopped pushing.
    void finish();

    const std::string& path() const noexcept { return path_; }
    int channels() const noexcept { return channels_; }
    double sampleRateHz() const noexcept { return sampleRateHz_; }
    /// Frames accepted by push() so far.
    std::uint64_t pushedFrames() const noexcept { return pushed_.load(); }
    /// Frames written to the file so far.
    std::uint64_t writtenFrames() const noexcept { return written_.load(); }
    /// Frames lost because the ring was full.
    std::uint64_t droppedFrames() const noexcept { return dropped_.load(); }
    /// A write error of the writer thread ("" when none); read after finish().
    const std::string& error() const noexcept { return error_; }

  private:
    struct Impl;
    void writerLoop();
    std::string path_;
    int channels_ = 0;
    double sampleRateHz_ = 0;
    float inverseScale_ = 1.0f;
    std::unique_ptr<Impl> impl_;
    std::atomic<std::uint64_t> pushed_{0}, written_{0}, dropped_{0};
    std::atomic<bool> stop_{false};
    std::string error_;
    std::thread writer_;
    std::atomic<bool> finished_{false};
};

} // namespace underfoot::engine
