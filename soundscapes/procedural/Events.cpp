// SPDX-License-Identifier: GPL-3.0-or-later
// One-shot events: animal calls as source-filter voices (a polyBLEP sawtooth or sine source with
// a pitch contour, shaped by one or two formant band-passes: gulls, hens, rooster, cows, dog,
// voices), FM-free sine glides for songbirds and the cuckoo, modal knocks (woodpecker, lift
// clank), and shaped noise (ski swishes and scrapes, leaves skittering).
#include "soundscapes/SynthKit.h"
#include "soundscapes/procedural/Procedural.h"

#include <array>

namespace underfoot::soundscapes::procedural {
namespace {

using engine::ProcessSpec;
using engine::Random;

// Shared mechanics: an event lasts `length_` samples; `sample(t)` gives its value at time t (s).
class VoiceBase : public EventVoice {
  public:
    void prepare(const ProcessSpec& spec) override { fs_ = spec.sampleRateHz; }
    void reset(std::uint64_t layerSeed, std::uint64_t voiceSeed) noexcept override {
        noise_.setSeed(voiceSeed);
        pos_ = length_ = 0;
        onReset(layerSeed);
    }
    int process(float* out, int n) noexcept override {
        int i = 0;
        for (; i < n && pos_ < length_; ++i, ++pos_)
            out[i] = static_cast<float>(sample(static_cast<double>(pos_) / fs_));
        snapState();
        return i;
    }

  protected:
    virtual void onReset(std::uint64_t) noexcept {}
    virtual double sample(double t) noexcept = 0;
    virtual void snapState() noexcept {}
    void setLengthSeconds(double s) noexcept {
        length_ = static_cast<long>(std::max(0.001, s) * fs_);
        pos_ = 0;
    }
    double fs_ = 48000.0;
    Random noise_;
    long pos_ = 0, length_ = 0;
};

// A series of calls (notes, barks, clucks): start time, duration and per-call values.
struct Call {
    double start = 0, dur = 0, a = 0, b = 0, c = 0, d = 0;
};
template <std::size_t N>
struct Series {
    std::array<Call, N> calls{};
    int count = 0;
    int current = 0;
    double total() const noexcept {
        return count > 0 ? calls[count - 1].start + calls[count - 1].dur : 0.0;
    }
    // The call sounding at time t, or nullptr in a gap; u gets the position in it (0..1).
    const Call* at(double t, double& u) noexcept {
        while (current < count && t >= calls[current].start + calls[current].dur) ++current;
        if (current >= count || t < calls[current].start) return nullptr;
        u = (t - calls[current].start) / calls[current].dur;
        return &calls[current];
    }
    void clear() noexcept { count = current = 0; }
    Call& add() noexcept { return calls[count < static_cast<int>(N) ? count++ : N - 1]; }
};

double lerp(double a, double b, double u) noexcept {
    return a + (b - a) * u;
}

// A voice whose event is a series of calls: silent in the gaps, `callSample` inside a call (u is
// the position in it, 0..1); `endAfterLastCall(tail)` ends the event tail seconds after the last.
template <std::size_t N>
class SeriesVoice : public VoiceBase {
  protected:
    double sample(double t) noexcept override {
        double u = 0;
        const Call* c = series_.at(t, u);
        return c ? callSample(*c, u) : 0.0;
    }
    virtual double callSample(const Call& c, double u) noexcept = 0;
    void endAfterLastCall(double tail) noexcept { setLengthSeconds(series_.total() + tail); }
    Series<N> series_;
};

// ---------------------------------------------------------------------------------------------
// Songbirds: a population of `species` songs drawn once from the layer seed (each song 3-8
// notes: sine glides of 30-180 ms between 0.6 and 2 times the pitch, some with a 25-70 Hz trill
// and a weak second harmonic); an event picks a species and sings its song 1-3 times with small
// variations, so the same birds recur, as in a real wood.
class SongbirdVoice final : public SeriesVoice<32> {
  public:
    explicit SongbirdVoice(const ParamSet& p)
        : species_(static_cast<int>(p.get("species"))), pitchHz_(p.get("pitch_hz")) {}
    void start(Random& rng) noexcept override {
        const Song& song = songs_[rng.below(static_cast<std::uint32_t>(species_))];
        const double scale = rng.uniform(0.96, 1.04);
        const int repeats =
            1 + static_cast<int>(rng.below(static_cast<std::uint32_t>(song.repeats)));
        series_.clear();
        double t = 0.0;
        for (int r = 0; r < repeats; ++r) {
            for (int k = 0; k < song.count; ++k) {
                const Note& note = song.notes[k];
                Call& c = series_.add();
                c.start = t;
                c.dur = note.dur * rng.uniform(0.92, 1.08);
                c.a = note.f0 * scale;
                c.b = note.f1 * scale;
                c.c = note.trillHz;
                c.d = note.trillDepth;
                t += c.dur + note.gap;
            }
            t += rng.uniform(0.15, 0.4);
        }
        osc_.reset();
        trill_.reset();
        endAfterLastCall(0.01);
    }

  protected:
    void onReset(std::uint64_t seed) noexcept override {
        Random r(seed); // the repertoire depends on the layer seed only
        for (int s = 0; s < species_; ++s) {
            Song& song = songs_[s];
            song.count = 3 + static_cast<int>(r.below(6));
            song.repeats = 1 + static_cast<int>(r.below(3));
            const double base = pitchHz_ * r.uniform(0.7, 1.4);
            for (int k = 0; k < song.count; ++k) {
                Note& n = song.notes[k];
                n.f0 = base * r.uniform(0.6, 2.0);
                n.f1 = n.f0 * std::exp2(r.uniform(-1.0, 1.0));
                n.dur = r.uniform(0.03, 0.18);
                n.gap = r.uniform(0.02, 0.09);
                const bool trill = r.uniform() < 0.3;
                n.trillHz = trill ? r.uniform(25.0, 70.0) : 0.0;
                n.trillDepth = trill ? r.uniform(0.05, 0.15) : 0.0;
            }
        }
    }
    double callSample(const Call& c, double u) noexcept override {
        const double trill = c.c > 0 ? c.d * trill_.next(c.c, fs_) : 0.0;
        const double f = lerp(c.a, c.b, u) * (1.0 + trill);
        const double phase = osc_.phase();
        const double y = osc_.next(f, fs_) + 0.15 * fastSin2Pi(2.0 * phase);
        return 0.8 * y * 4.0 * u * (1.0 - u); // close to sqrt(hann(u)) = sin(pi u)
    }

  private:
    struct Note {
        double f0 = 3000, f1 = 3000, dur = 0.1, gap = 0.05, trillHz = 0, trillDepth = 0;
    };
    struct Song {
        std::array<Note, 8> notes{};
        int count = 0, repeats = 1;
    };
    int species_;
    double pitchHz_;
    std::array<Song, 12> songs_{};
    SineOsc osc_, trill_;
};

// ---------------------------------------------------------------------------------------------
// Gull (herring-gull "kyow"): 2-6 calls of 0.18-0.4 s; each a harsh sawtooth whose pitch leaps
// up then falls below the start, through nasal formants near 1.8 and 3.2 kHz.
class GullVoice final : public SeriesVoice<8> {
  public:
    explicit GullVoice(const ParamSet& p) : pitchHz_(p.get("pitch_hz")) {}
    void start(Random& rng) noexcept override {
        series_.clear();
        const int calls = 2 + static_cast<int>(rng.below(5));
        const double pitch = pitchHz_ * rng.uniform(0.85, 1.15);
        double t = 0.0;
        for (int k = 0; k < calls; ++k) {
            Call& c = series_.add();
            c.start = t;
            c.dur = rng.uniform(0.18, 0.4);
            c.a = pitch * rng.uniform(0.9, 1.0);
            c.b = pitch * rng.uniform(1.2, 1.4);
            c.c = pitch * rng.uniform(0.75, 0.9);
            t += c.dur + rng.uniform(0.06, 0.25);
        }
        const double shift = rng.uniform(0.9, 1.1);
        f1_.set(fs_, 1800.0 * shift, 4.0);
        f2_.set(fs_, 3200.0 * shift, 5.0);
        f1_.reset();
        f2_.reset();
        saw_.reset();
        endAfterLastCall(0.02);
    }

  protected:
    double callSample(const Call& c, double u) noexcept override {
        const double f = u < 0.15 ? lerp(c.a, c.b, u / 0.15) : lerp(c.b, c.c, (u - 0.15) / 0.85);
        const double env = std::min(1.0, u * c.dur / 0.015) * std::min(1.0, (1.0 - u) / 0.3);
        const double s = saw_.next(f, fs_) + 0.2 * whiteNoise(noise_);
        return env * (f1_.bandNormalised(s) + 0.7 * f2_.bandNormalised(s) + 0.15 * s);
    }
    void snapState() noexcept override {
        f1_.snap();
        f2_.snap();
    }

  private:
    double pitchHz_;
    SawOsc saw_;
    Svf f1_, f2_;
};

// ---------------------------------------------------------------------------------------------
// Cuckoo: a series of 3-9 "cu-coo" pairs, about one per second; the second note a minor/major
// third below the first (ratio 0.80-0.86), soft sines with a weak second harmonic.
class CuckooVoice final : public SeriesVoice<20> {
  public:
    explicit CuckooVoice(const ParamSet& p) : pitchHz_(p.get("pitch_hz")) {}
    void start(Random& rng) noexcept override {
        series_.clear();
        const int pairs = 3 + static_cast<int>(rng.below(7));
        const double f = pitchHz_ * rng.uniform(0.95, 1.05);
        const double ratio = rng.uniform(0.8, 0.86);
        const double period = rng.uniform(0.85, 1.1);
        for (int k = 0; k < pairs; ++k) {
            Call& a = series_.add();
            a.start = k * period;
            a.dur = 0.13;
            a.a = f;
            Call& b = series_.add();
            b.start = a.start + 0.2;
            b.dur = 0.24;
            b.a = f * ratio;
        }
        osc_.reset();
        endAfterLastCall(0.01);
    }

  protected:
    double callSample(const Call& c, double u) noexcept override {
        const double f = c.a * (1.0 - 0.04 * u);
        const double phase = osc_.phase();
        const double y = osc_.next(f, fs_) + 0.12 * fastSin2Pi(2.0 * phase);
        const double env = std::min(1.0, u * c.dur / 0.02) * std::min(1.0, (1.0 - u) / 0.4);
        return 0.8 * y * env;
    }

  private:
    double pitchHz_;
    SineOsc osc_;
};

// ---------------------------------------------------------------------------------------------
// Woodpecker drumming: 10-24 knocks at 14-22 Hz on one trunk, each a 0.5 ms noise pulse into
// four modes (ratios 1, 1.72, 2.63, 3.91 of the base, decays 5-18 ms, varied per tree); the
// roll swells over three knocks then fades.
class WoodpeckerVoice final : public VoiceBase {
  public:
    explicit WoodpeckerVoice(const ParamSet& p)
        : baseHz_(p.get("base_hz")), rateHz_(p.get("rate_hz")) {}
    void start(Random& rng) noexcept override {
        knocks_ = 10 + static_cast<int>(rng.below(15));
        interval_ = 1.0 / (rateHz_ * rng.uniform(0.8, 1.2));
        static constexpr double ratios[4] = {1.0, 1.72, 2.63, 3.91};
        static constexpr double decays[4] = {0.018, 0.012, 0.008, 0.005};
        const double tree = rng.uniform(0.85, 1.15);
        for (int m = 0; m < 4; ++m) {
            // Two statements: the order of the draws is fixed, not the compiler's choice.
            const double decay = decays[m] * rng.uniform(0.8, 1.25);
            const double freq = baseHz_ * tree * ratios[m] * rng.uniform(0.97, 1.03);
            modes_[m].set(fs_, freq, decay);
            modes_[m].reset();
        }
        nextKnock_ = 0;
        k_ = 0;
        setLengthSeconds(knocks_ * interval_ + 0.08);
    }

  protected:
    double sample(double t) noexcept override {
        double x = 0.0;
        if (k_ < knocks_ && t >= nextKnock_) {
            if (t < nextKnock_ + 0.0005) {
                const double amp = std::min(1.0, (k_ + 1) / 3.0) * std::pow(0.93, k_);
                x = amp * whiteNoise(noise_) * 3.0;
            } else {
                ++k_;
                nextKnock_ += interval_ * (1.0 - 0.006 * k_); // a slight acceleration
            }
        }
        return modes_[0].process(x) + 0.7 * modes_[1].process(x) + 0.5 * modes_[2].process(x) +
               0.3 * modes_[3].process(x);
    }
    void snapState() noexcept override {
        for (auto& m : modes_) m.snap();
    }

  private:
    double baseHz_, rateHz_, interval_ = 0.05, nextKnock_ = 0;
    int knocks_ = 0, k_ = 0;
    std::array<Resonator, 4> modes_{};
};

// ---------------------------------------------------------------------------------------------
// Formant call: the common source-filter core of hens, rooster, cows, dogs and human shouts. A
// call carries its pitch contour (a -> b -> c at the knee u = d) and its own formants.
class FormantCore {
  public:
    void reset() noexcept {
        saw_.reset();
        f1_.reset();
        f2_.reset();
    }
    void setFormants(double fs, double f1, double q1, double f2, double q2) noexcept {
        f1_.set(fs, f1, q1);
        f2_.set(fs, f2, q2);
    }
    double next(double f0, double fs, double noiseMix, Random& rng, double f2Gain) noexcept {
        const double s = (1.0 - noiseMix) * saw_.next(f0, fs) + noiseMix * whiteNoise(rng);
        return f1_.bandNormalised(s) + f2Gain * f2_.bandNormalised(s);
    }
    void snap() noexcept {
        f1_.snap();
        f2_.snap();
    }

  private:
    SawOsc saw_;
    Svf f1_, f2_;
};

double contour(const Call& c, double u) noexcept {
    return u < c.d ? lerp(c.a, c.b, u / c.d) : lerp(c.b, c.c, (u - c.d) / (1.0 - c.d));
}

// A series of calls through one formant core, pitched from the `pitch_hz` parameter.
template <std::size_t N>
class FormantSeriesVoice : public SeriesVoice<N> {
  public:
    explicit FormantSeriesVoice(const ParamSet& p) : pitchHz_(p.get("pitch_hz")) {}

  protected:
    void snapState() noexcept override { core_.snap(); }
    double pitchHz_;
    FormantCore core_;
};

// How a short call (a cluck, a bark) sounds: a fast attack, an exponential decay over a share of
// the call, a linear release at its end (slope per unit of u), and the formant core's mix.
struct Burst {
    double attackS, decayShare, releaseSlope, noiseMix, f2Gain;
};

// Short calls on the call's pitch contour through fixed formants; `start` lays out the series.
template <std::size_t N>
class BurstSeriesVoice : public FormantSeriesVoice<N> {
  public:
    BurstSeriesVoice(const ParamSet& p, const Burst& burst)
        : FormantSeriesVoice<N>(p), burst_(burst) {}

  protected:
    double callSample(const Call& c, double u) noexcept override {
        const double env = attackDecay(u * c.dur, burst_.attackS, c.dur * burst_.decayShare) *
                           std::min(1.0, (1 - u) * burst_.releaseSlope);
        return env * this->core_.next(contour(c, u), this->fs_, burst_.noiseMix, this->noise_,
                                      burst_.f2Gain);
    }

  private:
    Burst burst_;
};

// Hen: 3-8 clucks ("buk") of 50-90 ms with falling pitch, sometimes ending in a "ba-GAWK".
class HenVoice final : public BurstSeriesVoice<12> {
  public:
    explicit HenVoice(const ParamSet& p)
        : BurstSeriesVoice(p, {.attackS = 0.006,
                               .decayShare = 0.45,
                               .releaseSlope = 8.0,
                               .noiseMix = 0.15,
                               .f2Gain = 0.6}) {}
    void start(Random& rng) noexcept override {
        series_.clear();
        const double p = pitchHz_ * rng.uniform(0.85, 1.15);
        const int clucks = 3 + static_cast<int>(rng.below(6));
        double t = 0.0;
        for (int k = 0; k < clucks; ++k) {
            Call& c = series_.add();
            c = {t, rng.uniform(0.05, 0.09), p * 1.3, p * 1.1, p * 0.85, 0.2};
            t += rng.uniform(0.18, 0.5);
        }
        if (rng.uniform() < 0.35) {
            Call& ba = series_.add();
            ba = {t, 0.08, p * 1.2, p * 1.3, p * 1.1, 0.5};
            Call& gawk = series_.add();
            gawk = {t + 0.12, rng.uniform(0.25, 0.4), p * 1.4, p * 1.9, p * 1.2, 0.35};
        }
        core_.reset();
        core_.setFormants(fs_, 950.0, 3.0, 2100.0, 4.0);
        endAfterLastCall(0.03);
    }
};

// Dog barks: 1-4 (sometimes up to 7) barks of 90-180 ms, pitch falling, a noisy harsh source.
class DogVoice final : public BurstSeriesVoice<8> {
  public:
    explicit DogVoice(const ParamSet& p)
        : BurstSeriesVoice(p, {.attackS = 0.008,
                               .decayShare = 0.4,
                               .releaseSlope = 6.0,
                               .noiseMix = 0.35,
                               .f2Gain = 0.7}) {}
    void start(Random& rng) noexcept override {
        series_.clear();
        const double p = pitchHz_ * rng.uniform(0.85, 1.15);
        const int barks = rng.uniform() < 0.3 ? 4 + static_cast<int>(rng.below(4))
                                              : 1 + static_cast<int>(rng.below(4));
        double t = 0.0;
        for (int k = 0; k < barks; ++k) {
            Call& c = series_.add();
            c = {t, rng.uniform(0.09, 0.18), p * 1.1, p * 1.2, p * 0.8, 0.15};
            t += rng.uniform(0.25, 0.45);
        }
        core_.reset();
        core_.setFormants(fs_, 800.0 * rng.uniform(0.9, 1.1), 2.5, 1800.0, 3.0);
        endAfterLastCall(0.02);
    }
};

// Rooster crow ("cock-a-doodle-doo"): four syllables of rising pitch, the last long and falling,
// with 6 Hz vibrato, each with its own vowel (F1 650-1000 Hz, F2 1500-2400 Hz) and some rasp.
class RoosterVoice final : public FormantSeriesVoice<4> {
  public:
    explicit RoosterVoice(const ParamSet& p) : FormantSeriesVoice(p) {}
    void start(Random& rng) noexcept override {
        series_.clear();
        const double p = pitchHz_ * rng.uniform(0.88, 1.12);
        static constexpr double durs[4] = {0.16, 0.18, 0.22, 0.85};
        static constexpr double from[4] = {0.95, 1.15, 1.25, 1.35};
        static constexpr double peak[4] = {1.1, 1.2, 1.3, 1.45};
        static constexpr double to[4] = {1.05, 1.15, 1.25, 0.9};
        double t = 0.0;
        for (int k = 0; k < 4; ++k) {
            Call& c = series_.add();
            c = {t, durs[k] * rng.uniform(0.9, 1.1), p * from[k], p * peak[k], p * to[k], 0.35};
            t += c.dur + 0.035;
        }
        core_.reset();
        vib_.reset();
        syllable_ = -1;
        endAfterLastCall(0.02);
    }

  protected:
    double callSample(const Call& c, double u) noexcept override {
        if (series_.current != syllable_) {
            static constexpr double f1[4] = {650, 800, 900, 1000}, f2[4] = {1500, 1900, 2200, 2400};
            syllable_ = series_.current;
            const int k = std::min(syllable_, 3);
            core_.setFormants(fs_, f1[k], 3.0, f2[k], 4.0);
        }
        const double f = contour(c, u) * (1.0 + 0.02 * vib_.next(6.0, fs_));
        const double env = std::min(1.0, u * c.dur / 0.015) * std::min(1.0, (1 - u) * c.dur / 0.04);
        return env * core_.next(f, fs_, 0.12, noise_, 0.7);
    }

  private:
    SineOsc vib_;
    int syllable_ = -1;
};

// Cow "moo": 1.2-2.4 s; low pitch rising then sinking; the mouth opens (F1 300 -> 650 Hz,
// F2 700 -> 1100 Hz) then closes; slow attack and release.
class CowVoice final : public VoiceBase {
  public:
    explicit CowVoice(const ParamSet& p) : pitchHz_(p.get("pitch_hz")) {}
    void start(Random& rng) noexcept override {
        dur_ = rng.uniform(1.2, 2.4);
        p_ = pitchHz_ * rng.uniform(0.85, 1.15);
        core_.reset();
        counter_ = 0;
        setLengthSeconds(dur_);
    }

  protected:
    double sample(double t) noexcept override {
        const double u = t / dur_;
        if (counter_-- <= 0) {
            counter_ = 32;
            const double open = u < 0.4 ? u / 0.4 : 1.0 - 0.6 * (u - 0.4) / 0.6;
            core_.setFormants(fs_, lerp(300.0, 650.0, open), 5.0, lerp(700.0, 1100.0, open), 6.0);
        }
        const double f =
            p_ * (u < 0.3 ? lerp(0.85, 1.1, u / 0.3) : lerp(1.1, 0.75, (u - 0.3) / 0.7));
        const double env = std::min(1.0, t / 0.25) * std::min(1.0, (dur_ - t) / 0.35);
        return env * core_.next(f, fs_, 0.06, noise_, 0.5);
    }
    void snapState() noexcept override { core_.snap(); }

  private:
    double pitchHz_, dur_ = 1, p_ = 120;
    FormantCore core_;
    int counter_ = 0;
};

// A distant human call or a child's shout: 2-5 syllables (0.12-0.35 s) with exaggerated rising
// and falling contours and random vowels, low-passed by distance.
class ShoutVoice final : public FormantSeriesVoice<6> {
  public:
    explicit ShoutVoice(const ParamSet& p)
        : FormantSeriesVoice(p), distanceHz_(p.get("distance_hz")) {}
    void start(Random& rng) noexcept override {
        series_.clear();
        const double p = pitchHz_ * rng.uniform(0.85, 1.2);
        const int syl = 2 + static_cast<int>(rng.below(4));
        double t = 0.0;
        for (int k = 0; k < syl; ++k) {
            Call& c = series_.add();
            const double up = rng.uniform(0.9, 1.4);
            c = {t, rng.uniform(0.12, 0.35), p, p * up, p * rng.uniform(0.7, 1.0), 0.4};
            t += c.dur + rng.uniform(0.03, 0.15);
        }
        for (int k = 0; k < syl; ++k) {
            vowels_[k][0] = rng.uniform(500.0, 1000.0);
            vowels_[k][1] = rng.uniform(1200.0, 2600.0);
        }
        core_.reset();
        dist_.reset();
        dist_.set(fs_, distanceHz_, 0.7);
        syllable_ = -1;
        endAfterLastCall(0.02);
    }

  protected:
    // The distance low-pass runs through the gaps too (its tail rings on).
    double sample(double t) noexcept override { return dist_.process(SeriesVoice::sample(t)).low; }
    double callSample(const Call& c, double u) noexcept override {
        if (series_.current != syllable_) {
            syllable_ = series_.current;
            core_.setFormants(fs_, vowels_[syllable_][0], 4.0, vowels_[syllable_][1], 6.0);
        }
        const double env = 4.0 * u * (1.0 - u);
        return env * core_.next(contour(c, u), fs_, 0.1, noise_, 0.6);
    }
    void snapState() noexcept override {
        core_.snap();
        dist_.snap();
    }

  private:
    double distanceHz_;
    std::array<std::array<double, 2>, 6> vowels_{};
    Svf dist_;
    int syllable_ = -1;
};

// ---------------------------------------------------------------------------------------------
// Ski swish: a skier's 1-4 turns, each 0.6-1.3 s of white noise through a band-pass that
// sweeps up and back (the edge biting, then releasing), with granular amplitude flutter
// (snow crystals) and a low carving component.
class SwishVoice final : public VoiceBase {
  public:
    explicit SwishVoice(const ParamSet& p)
        : brightHz_(p.get("brightness_hz")), turns_(static_cast<int>(p.get("turns_max"))) {}
    void prepare(const ProcessSpec& spec) override {
        VoiceBase::prepare(spec);
        grain_.configure(0.012, 0.004, fs_);
    }
    void start(Random& rng) noexcept override {
        series_.clear();
        const int turns = 1 + static_cast<int>(rng.below(static_cast<std::uint32_t>(turns_)));
        double t = 0;
        for (int k = 0; k < turns; ++k) {
            Call& c = series_.add();
            c = {t, rng.uniform(0.6, 1.3), brightHz_ * rng.uniform(0.8, 1.25), 0, 0, 0};
            t += c.dur + rng.uniform(0.15, 0.6);
        }
        band_.reset();
        carve_.reset();
        carve_.set(fs_, 400.0, 0.7);
        grain_.reset(noise_);
        counter_ = 0;
        setLengthSeconds(series_.total() + 0.01);
    }

  protected:
    double sample(double t) noexcept override {
        double u = 0;
        const Call* c = series_.at(t, u);
        const double w = whiteNoise(noise_);
        const double g = grain_.next(noise_);
        if (!c) {
            band_.process(0.0);
            return 0.0;
        }
        if (counter_-- <= 0) {
            counter_ = 16;
            band_.set(fs_, c->a * (0.5 + hann(u)), 1.2);
            shape_ = std::pow(hann(u), 0.7);
        }
        const double env = shape_ * (0.6 + 0.4 * g);
        return env * (band_.bandNormalised(w) + 0.5 * carve_.process(w).low);
    }
    void snapState() noexcept override {
        band_.snap();
        carve_.snap();
    }

  private:
    double brightHz_;
    int turns_;
    Series<8> series_;
    Svf band_, carve_;
    SmoothRandom grain_;
    int counter_ = 0;
    double shape_ = 0.0;
};

// Ski scrape on icy snow: 0.3-0.9 s of noise through two narrow resonances (the edge
// chattering) with 40-80 Hz chatter modulation over a broadband hiss.
class ScrapeVoice final : public VoiceBase {
  public:
    explicit ScrapeVoice(const ParamSet& p) : brightHz_(p.get("brightness_hz")) {}
    void start(Random& rng) noexcept override {
        dur_ = rng.uniform(0.3, 0.9);
        const double f = brightHz_ * rng.uniform(0.85, 1.2);
        r1_.reset();
        r2_.reset();
        hp_.reset();
        r1_.set(fs_, f, 8.0);
        r2_.set(fs_, f * 1.45, 6.0);
        hp_.set(fs_, 1500.0, 0.7);
        chatterHz_ = rng.uniform(40.0, 80.0);
        chatter_.reset();
        counter_ = 0;
        setLengthSeconds(dur_);
    }

  protected:
    double sample(double t) noexcept override {
        const double u = t / dur_;
        const double w = whiteNoise(noise_);
        const double ch = 0.5 + 0.5 * std::fabs(chatter_.next(chatterHz_, fs_));
        if (counter_-- <= 0) {
            counter_ = 16;
            shape_ = std::pow(std::max(0.0, 1.0 - u), 0.8);
        }
        const double env = std::min(1.0, t / 0.03) * shape_;
        return env * (ch * (r1_.bandNormalised(w) + 0.7 * r2_.bandNormalised(w)) +
                      0.3 * hp_.process(w).high);
    }
    void snapState() noexcept override {
        r1_.snap();
        r2_.snap();
        hp_.snap();
    }

  private:
    double brightHz_, dur_ = 0.5, chatterHz_ = 50, shape_ = 0.0;
    Svf r1_, r2_, hp_;
    SineOsc chatter_;
    int counter_ = 0;
};

// Chairlift pylon clank ("ka-chunk" of a chair's grip over the sheave train): two knocks 0.12-
// 0.2 s apart into four inharmonic metal modes (free-bar ratios 1, 2.76, 5.40, 8.93; decays
// 50-250 ms) and a low 90 Hz thump.
class ClankVoice final : public VoiceBase {
  public:
    explicit ClankVoice(const ParamSet& p) : baseHz_(p.get("base_hz")) {}
    void start(Random& rng) noexcept override {
        static constexpr double ratios[4] = {1.0, 2.76, 5.40, 8.93};
        static constexpr double decays[4] = {0.25, 0.15, 0.08, 0.05};
        const double f = baseHz_ * rng.uniform(0.95, 1.05);
        for (int m = 0; m < 4; ++m) {
            modes_[m].reset();
            modes_[m].set(fs_, f * ratios[m], decays[m]);
        }
        thump_.reset();
        thump_.set(fs_, 90.0, 0.06);
        second_ = rng.uniform(0.12, 0.2);
        secondGain_ = rng.uniform(0.6, 1.0);
        setLengthSeconds(second_ + 0.9);
    }

  protected:
    double sample(double t) noexcept override {
        double x = 0.0;
        if (t < 0.002)
            x = whiteNoise(noise_) * 2.0;
        else if (t >= second_ && t < second_ + 0.002)
            x = whiteNoise(noise_) * 2.0 * secondGain_;
        return modes_[0].process(x) + 0.6 * modes_[1].process(x) + 0.4 * modes_[2].process(x) +
               0.25 * modes_[3].process(x) + 1.5 * thump_.process(x);
    }
    void snapState() noexcept override {
        for (auto& m : modes_) m.snap();
        thump_.snap();
    }

  private:
    double baseHz_, second_ = 0.15, secondGain_ = 1;
    std::array<Resonator, 4> modes_{};
    Resonator thump_;
};

// Leaves skittering over a path: 0.4-1.5 s bursts of Poisson crackles (80-300 per second), each
// a 1.5 ms decaying noise grain (a leaf edge scraping) ringing a dry band near `brightness_hz`,
// swelling and fading like a gust pushing a leaf along.
class SkitterVoice final : public VoiceBase {
  public:
    explicit SkitterVoice(const ParamSet& p) : brightHz_(p.get("brightness_hz")) {}
    void start(Random& rng) noexcept override {
        dur_ = rng.uniform(0.4, 1.5);
        rate_ = rng.uniform(80.0, 300.0);
        band_.reset();
        band_.set(fs_, brightHz_ * rng.uniform(0.8, 1.25), 1.2);
        grain_ = 0.0;
        decay_ = std::exp(-1.0 / (0.0015 * fs_));
        setLengthSeconds(dur_);
    }

  protected:
    double sample(double t) noexcept override {
        const double env = hann(t / dur_);
        if (noise_.uniform() < rate_ * env / fs_) grain_ = noise_.uniform(0.3, 1.0);
        grain_ *= decay_;
        return band_.bandNormalised(grain_ * whiteNoise(noise_));
    }
    void snapState() noexcept override { band_.snap(); }

  private:
    double brightHz_, dur_ = 1, rate_ = 100, grain_ = 0, decay_ = 0.99;
    Svf band_;
};

// The factories that Procedural.h declares (constant-initialised: usable at any time).
template <class Generator>
std::unique_ptr<EventVoice> makeVoice(const ParamSet& p) {
    return std::make_unique<Generator>(p);
}

} // namespace

constinit const VoiceFactory makeSongbird = makeVoice<SongbirdVoice>;
constinit const VoiceFactory makeGull = makeVoice<GullVoice>;
constinit const VoiceFactory makeCuckoo = makeVoice<CuckooVoice>;
constinit const VoiceFactory makeWoodpecker = makeVoice<WoodpeckerVoice>;
constinit const VoiceFactory makeHen = makeVoice<HenVoice>;
constinit const VoiceFactory makeRooster = makeVoice<RoosterVoice>;
constinit const VoiceFactory makeCow = makeVoice<CowVoice>;
constinit const VoiceFactory makeDog = makeVoice<DogVoice>;
constinit const VoiceFactory makeSwish = makeVoice<SwishVoice>;
constinit const VoiceFactory makeScrape = makeVoice<ScrapeVoice>;
constinit const VoiceFactory makeClank = makeVoice<ClankVoice>;
constinit const VoiceFactory makeShout = makeVoice<ShoutVoice>;
constinit const VoiceFactory makeSkitter = makeVoice<SkitterVoice>;

} // namespace underfoot::soundscapes::procedural
