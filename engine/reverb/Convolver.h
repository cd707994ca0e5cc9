// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Zero-latency convolution reverb: mono in, stereo out (a mono IR feeds both sides).
///
/// A non-uniformly partitioned convolution whose FFT work is spread in time, deterministically,
/// on the calling (audio) thread (Gardner 1995, "Efficient convolution without input-output
/// delay", JAES 43(3); Garcia 2002, "Optimal filter partition for efficient convolution with
/// short input/output delay", AES 113th conv. 5660; Wefers 2015, "Partitioned convolution
/// algorithms for real-time auralization", ch. 5, time-distributed FFTs):
///  - taps [0, 64) run as a direct-form FIR, sample by sample, so an impulse at input sample 0
///    is heard at output sample 0 whatever the block size;
///  - taps [64, 512) run in a uniformly partitioned overlap-save stage with partition P = 64,
///    computed at once each time 64 input samples are complete (it starts at tap T = P);
///  - taps [512, 4096) run in a stage with P = 256 and taps [4096, end) in one with P = 2048.
///    Such a stage starts at tap T = 2P: the output of input block k (samples [kP, (k+1)P)) is
///    first needed at sample kP + T = (k+2)P, so its work (one forward FFT of 2P points, one
///    complex multiply-add per bin, partition and channel, the inverse FFT: for a stereo IR one
///    complex FFT of L + i R, whose real and imaginary parts are l and r) may take
///    the whole next period. It is cut into P / 64 slices (a schedule fixed in prepare() by
///    estimated cost; order: the products of the older spectra, the forward FFT, the newest
///    product, the inverse FFTs), and one slice runs every 64 input samples.
///  - In stages with P >= 1024 no piece of that work is large against a slice (worst
///    64-frame block <= 2x the median on short IRs too): the 2P-point FFTs are complex
///    "four-step" FFTs (Bailey 1990: 2P / 64 DFTs of 64 points, twiddles, 64 DFTs of 2P / 64
///    points; FFTW plans of a few DFTs each, run one group per piece), both output channels share
///    one inverse (left + i right), and the products are cut into bin ranges. The order of the
///    operations per bin does not depend on the cut, so the output stays the same for any block.
///  - The spectra are stored in records of 8 bins (per record: a partition's or input slot's 8
///    real parts, then 8 imaginary parts), so that a product over all of a stage's older
///    partitions reads its bins contiguously and keeps its sums in registers; its work is cut by
///    bin ranges (hall 789 -> 672 instructions a sample, the same output).
/// Work is tied to the count of input samples only (a "tick" every 64 samples), never to the
/// host block: the output is bit-identical for every block size (replay relies on it).
/// FFTs: FFTW single precision, FFTW_ESTIMATE plans (deterministic; planned under a lock).
/// process() allocates nothing, takes no lock, does not wait and flushes denormals.
#include "engine/io/AudioFile.h"
#include "engine/reverb/ImpulseResponses.h" // findImpulseResponse(), for users of the convolver

#include <cstdint>
#include <memory>
#include <vector>

namespace underfoot::engine {

class Convolver {
  public:
    static constexpr int kHeadLength = 64; ///< direct-form taps
    static constexpr int kTick = 64;       ///< samples between two slices of FFT work
    /// Partition sizes of the FFT stages, in order. Stage 0 starts at tap kHeadLength; stage
    /// i > 0 starts at tap 2 x its partition (2 x 256 = 512, 2 x 2048 = 4096).
    static constexpr int kPartitions[3] = {64, 256, 2048};

    Convolver();
    ~Convolver();
    Convolver(const Convolver&) = delete;
    Convolver& operator=(const Convolver&) = delete;

    /// Allocates and loads the IR (1 or 2 channels), resampled with libsamplerate when its rate
    /// differs from sampleRateHz (and scaled by the rate ratio so that the filter's frequency
    /// response, not its sum of taps, is kept). Throws std::invalid_argument for an empty IR,
    /// more than two channels, non-finite taps or a bad rate, std::runtime_error when FFTW
    /// cannot plan. `blockSize` is the largest n passed to process() (any n works; the output
    /// does not depend on it).
    void prepare(const AudioBuffer& impulseResponse, double sampleRateHz, int blockSize);
    /// Clears the signal history (no allocation: usable wherever process() is).
    void reset() noexcept;
    /// Instruction sets of the products and of the direct head. Every level does per bin and
    /// per output the same IEEE operations in the same order (no FMA): the output is
    /// bit-identical whichever level the CPU runs (tested).
    enum class Simd { Sse = 0, Avx = 1, Avx512 = 2 };
    /// The widest level the next prepare() may use (default: the widest the CPU has). For tests
    /// and benchmarks.
    void limitSimd(Simd limit) noexcept { simdLimit_ = limit; }
    /// The level prepare() chose.
    Simd simd() const noexcept { return simd_; }

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
    void tick() noexcept;

    AudioBuffer ir_;
    std::size_t irLength_ = 0;
    bool stereoIr_ = false;
    Simd simd_ = Simd::Sse;            ///< kernels in use (all bit-identical)
    Simd simdLimit_ = Simd::Avx512;    ///< the widest level prepare() may choose
    std::vector<float> headL_, headR_; ///< the first kHeadLength taps
    std::vector<float> line_;          ///< the 63 previous inputs, then the current run
    int phase_ = 0;                    ///< input samples since the last tick, 0 .. kTick - 1
    std::vector<std::unique_ptr<Stage>> stages_;
};

/// Offline convolution of a mono signal with an IR (any rate; resampled to sampleRateHz):
/// stereo output of input length + IR length - 1 samples, through the same Convolver.
AudioBuffer convolveOffline(const std::vector<float>& input, double sampleRateHz,
                            const AudioBuffer& impulseResponse);

} // namespace underfoot::engine
