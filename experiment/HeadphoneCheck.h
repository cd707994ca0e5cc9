// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The headphone check of online tests, scored by the server: the antiphase test of Woods,
/// Siegel, Traer & McDermott (2017, Attention, Perception & Psychophysics 79:2064). Each triplet
/// plays three 200 Hz tones; one is 6 dB quieter, and one of the two others is in antiphase
/// between the ears (quieter over loudspeakers, not over headphones); the participant names the
/// quiet one. The layout (which interval is quiet, which antiphase) comes from a seeded
/// generator, so the stored seed replays the layout and every sample of the tones. The page
/// only gets the rendered tones and sends the participant's choice; this class scores.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace underfoot::experiment {

class HeadphoneCheck {
  public:
    /// Triplets in one check and correct answers needed to pass (Woods et al. 2017: 5 of 6).
    static constexpr int kTriplets = 6;
    static constexpr int kPassMark = 5;
    /// The served tones: 16-bit stereo PCM WAV at this rate; three 1 s tones 0.5 s apart.
    static constexpr int kSampleRateHz = 22050;
    static constexpr double kToneSeconds = 1.0;
    static constexpr double kGapSeconds = 0.5;
    /// Frames of one triplet's audio (3 tones, 2 gaps).
    static int tripletFrames();
    /// Seconds of one triplet's audio (4.0).
    static double tripletSeconds();

    /// One triplet: the quiet interval and the antiphase interval (0, 1 or 2, different).
    struct Triplet {
        int quiet = 0;
        int antiphase = 1;
    };
    /// The layout drawn from `seed` (xoshiro256**, experiment/Random.h).
    static std::vector<Triplet> layout(std::uint64_t seed, int triplets = kTriplets);
    /// A triplet's samples, interleaved stereo (left, right), as 16-bit integers.
    static std::vector<std::int16_t> render(const Triplet& t);
    /// The same samples as a complete WAV file (RIFF header + PCM data).
    static std::string wav(const Triplet& t);

    /// A check laid out from `seed`; answers sooner than `minResponseSeconds` after their
    /// tones are refused (default: the tones' length; tests of the server shorten it).
    explicit HeadphoneCheck(std::uint64_t seed, double minResponseSeconds = tripletSeconds());
    std::uint64_t seed() const { return seed_; }
    double minResponseSeconds() const { return minResponse_; }
    const std::vector<Triplet>& triplets() const { return layout_; }
    /// Index of the triplet waiting for an answer (== kTriplets when every one is answered).
    int next() const { return static_cast<int>(choices_.size()); }
    bool done() const { return next() >= kTriplets; }
    /// Records the choice (1, 2 or 3: the interval named quietest) for triplet `index`; returns
    /// a message naming what was expected when refused (not the next triplet, choice outside
    /// 1..3, tones never served, answered sooner than minResponseSeconds() after its tones),
    /// nullopt when recorded. `secondsSinceTones`: time since the triplet's tones were served
    /// (nullopt: never served).
    std::optional<std::string> answer(int index, int choice,
                                      std::optional<double> secondsSinceTones);
    const std::vector<int>& choices() const { return choices_; }
    int correct() const;
    bool passed() const { return done() && correct() >= kPassMark; }

  private:
    std::uint64_t seed_;
    double minResponse_;
    std::vector<Triplet> layout_;
    std::vector<int> choices_;
};

} // namespace underfoot::experiment
