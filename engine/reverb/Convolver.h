// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Zero-latency convolution reverb: mono in, stereo out (a mono IR feeds both sides).
///
/// Structure (Gardner 1995, "Efficient convolution without input-output delay", JAES 43(3)):
///  - taps [0, 64) run as a direct-form FIR, sample by sample, so an impulse at input sample 0
///    is heard at output sample 0 whatever the block size;
///  - taps [64, 1024) run in a zita-convolver instance (Fons Adriaensen, API 4.x) with quantum =
///    partition = 64, and taps [1024, end) in a second one with quantum = partition = 1024.
///    A stage with partition P is given its taps shifted P earlier, so its output for input
///    block k is exactly those taps' contribution to block k + 1, which is buffered and added
///    during the next P samples: no added latency. (A stage may start at tap T only if T >= P.)
/// Why one partition size per zita instance: zita-convolver computes its larger partitions in
/// worker threads, and a level whose thread is not running yet (or could not be created, e.g.
/// SCHED_FIFO without privileges) is computed inline one partition too early, silently giving
/// wrong output; the thread start is a race its API does not let us observe. With quantum =
/// minpart = maxpart zita runs no thread at all (Convproc::start_process skips level 0), so every
/// sample is computed on the calling thread: deterministic, identical for every host block size,
/// no locks, no waiting, no allocation in process(). (The thread policy passed is SCHED_OTHER.)
/// Cost: the 1024-sample stage does its work once every 1024 samples (a burst of about three
/// 2048-point FFTs plus one complex multiply-add per bin and partition).
#include "engine/io/AudioFile.h"
#include "engine/reverb/ImpulseResponses.h" // findImpulseResponse(), for users of the convolver

#include <memory>
#include <vector>

class Convproc;

namespace underfoot::engine {

class Convolver {
  public:
    static constexpr int kHeadLength = 64;      ///< direct-form taps
    static constexpr int kLongPartition = 1024; ///< partition of the late stage

    Convolver();
    ~Convolver();
    Convolver(const Convolver&) = delete;
    Convolver& operator=(const Convolver&) = delete;

    /// Allocates and loads the IR (1 or 2 channels), resampled with libsamplerate when its rate
    /// differs from sampleRateHz (and scaled by the rate ratio so that the filter's frequency
    /// response, not its sum of taps, is kept). Throws std::invalid_argument for an empty IR,
    /// more than two channels, non-finite taps or a bad rate, std::runtime_error when
    /// zita-convolver refuses the configuration. `blockSize` is the largest n passed to
    /// process() (any n up to it works; the output does not depend on it).
    void prepare(const AudioBuffer& impulseResponse, double sampleRateHz, int blockSize);
    /// Clears the signal history (not for the audio thread).
    void reset();
    /// Mono in, stereo out; in may alias outL or outR. No allocation, no locks, no waiting.
    void process(const float* in, float* outL, float* outR, int n) noexcept;

    /// IR length in samples at the processing rate (0 before prepare()).
    std::size_t impulseLength() const noexcept { return irLength_; }
    /// Partition sizes of the FFT stages in use (empty when the IR fits in the direct head).
    std::vector<int> partitionSizes() const;
    /// The IR actually used (after resampling), interleaved stereo.
    const AudioBuffer& impulseResponse() const noexcept { return ir_; }

  private:
    struct Stage;
    void release() noexcept;

    AudioBuffer ir_;
    std::size_t irLength_ = 0;
    std::vector<float> headL_, headR_; ///< first taps, reversed for the dot product
    std::vector<float> history_;       ///< last kHeadLength inputs, stored twice (no wrap)
    int historyPos_ = 0;
    std::vector<std::unique_ptr<Stage>> stages_;
};

/// Offline convolution of a mono signal with an IR (any rate; resampled to sampleRateHz):
/// stereo output of input length + IR length - 1 samples, through the same Convolver.
AudioBuffer convolveOffline(const std::vector<float>& input, double sampleRateHz,
                            const AudioBuffer& impulseResponse);

} // namespace underfoot::engine
