// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Zero-latency convolution reverb: mono in, stereo out (a mono IR feeds both sides).
///
/// Structure (Gardner 1995, "Efficient convolution without input-output delay", JAES 43(3)):
///  - the first Q taps of the IR run as a direct-form FIR, sample by sample, so an impulse at
///    input sample 0 is heard at output sample 0 whatever the block size;
///  - the rest of the IR runs in zita-convolver (Fons Adriaensen, API 4.x) as a uniformly
///    partitioned FFT convolution with quantum = partition = Q. It is fed the IR from tap Q on,
///    so its output for input block k is exactly the tail's contribution to block k + 1, which
///    is buffered and added during the next Q samples: no added latency.
/// Q = the power of two nearest sqrt(IR length), clamped to [64, 1024] (balances the direct
/// head's Q MACs per sample against the L/Q complex MACs per sample of the partitions).
/// Why a single partition size: zita-convolver computes larger partitions in worker threads and
/// a level whose thread is not running yet (or could not be created, e.g. SCHED_FIFO without
/// privileges) is computed inline one partition too early, silently giving wrong output; the
/// thread start is a race we cannot observe through its API. With quantum = minpart = maxpart
/// zita runs no thread at all (Convproc::start_process skips level 0), so every sample is
/// computed on the calling thread: deterministic, identical for every host block size, and
/// still no locks or allocation in process(). The thread policy passed is SCHED_OTHER anyway.
#include "engine/io/AudioFile.h"
#include "engine/reverb/ImpulseResponses.h" // findImpulseResponse(), for users of the convolver

#include <memory>
#include <vector>

class Convproc;

namespace underfoot::engine {

class Convolver {
  public:
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
    /// Clears the signal history (not for the audio thread: zita-convolver's reset is not
    /// documented as real-time safe).
    void reset();
    /// Mono in, stereo out; in may alias outL or outR. No allocation, no locks, no waiting.
    void process(const float* in, float* outL, float* outR, int n) noexcept;

    /// IR length in samples at the processing rate (0 before prepare()).
    std::size_t impulseLength() const noexcept { return irLength_; }
    /// Q: direct-form taps = FFT partition size (see above).
    int headLength() const noexcept { return q_; }
    /// The IR actually used (after resampling), interleaved stereo.
    const AudioBuffer& impulseResponse() const noexcept { return ir_; }

  private:
    void release() noexcept;

    std::unique_ptr<Convproc> zita_;
    bool hasTail_ = false;
    int q_ = 64;
    AudioBuffer ir_;
    std::size_t irLength_ = 0;
    std::vector<float> headL_, headR_; ///< first taps, reversed for the dot product
    std::vector<float> history_;       ///< last Q inputs, stored twice (no wrap)
    int historyPos_ = 0;
    std::vector<float> tailL_, tailR_; ///< tail output for the current Q-sample block
    int fill_ = 0;                     ///< samples of the current block already consumed
};

/// Offline convolution of a mono signal with an IR (any rate; resampled to sampleRateHz):
/// stereo output of input length + IR length - 1 samples, through the same Convolver.
AudioBuffer convolveOffline(const std::vector<float>& input, double sampleRateHz,
                            const AudioBuffer& impulseResponse);

} // namespace underfoot::engine
