// SPDX-License-Identifier: GPL-3.0-or-later
// Continuous textures: filtered noise with slow random modulation (sea, wind, leaves, traffic),
// formant-filtered pulse trains (babble), and engine/machinery tones (tractor, lift).
#include "soundscapes/SynthKit.h"
#include "soundscapes/procedural/Procedural.h"

#include <array>

namespace underfoot::soundscapes::procedural {
namespace {

using engine::ProcessSpec;
using engine::Random;

constexpr int kControlInterval = 16; // samples between filter retunings

// Shared mechanics: the sample rate, and the bed's one random stream, seeded at each reset
// before the bed restarts its own state.
class BedBase : public BedGenerator {
  public:
    void prepare(const ProcessSpec& spec) override {
        fs_ = spec.sampleRateHz;
        onPrepare();
    }
    void reset(std::uint64_t seed) noexcept override {
        rng_.setSeed(seed);
        onReset();
    }

  protected:
    virtual void onPrepare() {}
    virtual void onReset() noexcept = 0;
    double fs_ = 48000.0;
    Random rng_;
};

// ---------------------------------------------------------------------------------------------
// Sea: each wave is a swell (quadratic rise over 30 % of its period) that breaks and washes out
// exponentially. The swell opens a low-pass on pink noise (the roar) and, as it breaks, lets
// high-passed white noise through (the foam). The right channel hears the same waves a little
// later (the wave breaks along the shore), with its own noise.
class SeaBed final : public BedBase {
  public:
    explicit SeaBed(const ParamSet& p)
        : periodS_(p.get("wave_period_s")), brightHz_(p.get("brightness_hz")),
          foam_(p.get("foam")) {}
    void onReset() noexcept override {
        for (auto& c : ch_) {
            c.pink.reset();
            c.body.reset();
            c.foamHp.reset();
            c.rumble.reset();
            c.foamHp.set(fs_, 2500.0, 0.7);
            c.rumble.set(fs_, 250.0, 0.7);
        }
        prevPeak_ = 0.7;
        newWave();
        pos_ = static_cast<long>(rng_.uniform() * static_cast<double>(len_));
        counter_ = 0;
        envNow_[0] = envAt(static_cast<double>(pos_) / static_cast<double>(len_));
        envNow_[1] = envAt(static_cast<double>(pos_) / static_cast<double>(len_) - shift_);
    }
    void process(float* left, float* right, int n) noexcept override {
        float* out[2] = {left, right};
        for (int i = 0; i < n; ++i) {
            if (counter_-- <= 0) {
                // Envelopes and filters at control rate, the gain ramped linearly in between.
                counter_ = kControlInterval - 1;
                const double u =
                    static_cast<double>(pos_ + kControlInterval) / static_cast<double>(len_);
                for (int c = 0; c < 2; ++c) {
                    const double target = envAt(c == 0 ? u : u - shift_);
                    envStep_[c] = (target - envNow_[c]) / kControlInterval;
                    ch_[c].body.set(fs_, 120.0 + brightHz_ * target * target, 0.6);
                }
            }
            envNow_[0] += envStep_[0];
            envNow_[1] += envStep_[1];
            const double env[2] = {envNow_[0], envNow_[1]};
            for (int c = 0; c < 2; ++c) {
                auto& s = ch_[c];
                const double pink = s.pink.next(rng_);
                const double roar = s.body.process(pink).low * env[c];
                const double foam =
                    s.foamHp.process(whiteNoise(rng_)).high * foam_ * env[c] * env[c] * env[c];
                const double bed = 0.35 * s.rumble.process(pink).low;
                out[c][i] = static_cast<float>(roar + 0.5 * foam + bed);
            }
            if (++pos_ >= len_) {
                prevPeak_ = peak_;
                newWave();
                pos_ = 0;
            }
        }
        for (auto& c : ch_) {
            c.body.snap();
            c.foamHp.snap();
            c.rumble.snap();
        }
    }

  private:
    void newWave() noexcept {
        len_ = static_cast<long>(periodS_ * rng_.uniform(0.7, 1.3) * fs_);
        peak_ = rng_.uniform(0.55, 1.0);
        shift_ = rng_.uniform(0.02, 0.08);
    }
    // Envelope at position u of the current wave (u < 0: the tail of the previous one).
    double envAt(double u) const noexcept {
        constexpr double floor = 0.15, rise = 0.3, wash = 0.2;
        if (u < 0.0) return floor + (prevPeak_ - floor) * std::exp(-(u + 1.0 - rise) / wash);
        if (u < rise) {
            const double tail = (prevPeak_ - floor) * std::exp(-(u + 1.0 - rise) / wash);
            const double r = u / rise;
            return floor + tail + (peak_ - floor) * r * r;
        }
        return floor + (peak_ - floor) * std::exp(-(u - rise) / wash);
    }
    struct Channel {
        PinkNoise pink;
        Svf body, foamHp, rumble;
    };
    double periodS_, brightHz_, foam_;
    std::array<Channel, 2> ch_{};
    long len_ = 1, pos_ = 0;
    double peak_ = 0.7, prevPeak_ = 0.7, shift_ = 0.05;
    double envNow_[2] = {0, 0}, envStep_[2] = {0, 0};
    int counter_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Wind: white noise through a band-pass whose centre and level follow a slow random gust signal
// (Farnell, "Designing Sound", ch. 40, reduced to one band); a low rumble of pink noise and an
// optional narrow whistle band that only speaks in strong gusts.
class WindBed final : public BedBase {
  public:
    explicit WindBed(const ParamSet& p)
        : centreHz_(p.get("centre_hz")), gust_(p.get("gustiness")), whistle_(p.get("whistle")) {}
    void onPrepare() override {
        // Modulators run at the control rate (one step per kControlInterval samples).
        const double controlRate = fs_ / kControlInterval;
        gustMod_.configure(2.5, 1.0, controlRate);
        for (auto& c : ch_) c.mod.configure(1.0, 0.4, controlRate);
    }
    void onReset() noexcept override {
        gustMod_.reset(rng_);
        for (auto& c : ch_) {
            c.mod.reset(rng_);
            c.band.reset();
            c.whistle.reset();
            c.rumble.reset();
            c.pink.reset();
            c.rumble.set(fs_, 140.0, 0.7);
            c.amp = c.ampStep = c.wh = c.whStep = 0.0;
        }
        counter_ = 0;
    }
    void process(float* left, float* right, int n) noexcept override {
        float* out[2] = {left, right};
        for (int i = 0; i < n; ++i) {
            if (counter_-- <= 0) {
                counter_ = kControlInterval - 1;
                const double g = gustMod_.next(rng_);
                for (auto& s : ch_) {
                    const double m = 0.75 * g + 0.25 * s.mod.next(rng_);
                    const double f = centreHz_ * std::exp2(1.6 * (m - 0.5));
                    s.band.set(fs_, f, 0.9);
                    if (whistle_ > 0.0) s.whistle.set(fs_, 3.1 * f, 14.0);
                    const double amp = (1.0 - gust_) + gust_ * m * m * 1.8;
                    s.ampStep = (amp - s.amp) / kControlInterval;
                    s.whStep = (whistle_ * m * m * m * 0.6 - s.wh) / kControlInterval;
                }
            }
            for (int c = 0; c < 2; ++c) {
                auto& s = ch_[c];
                s.amp += s.ampStep;
                s.wh += s.whStep;
                const double w = whiteNoise(rng_);
                // The rumble is the pink-filtered same noise: its band (< 140 Hz) does not
                // overlap the wind band, so one noise source serves both.
                const double body =
                    s.band.bandNormalised(w) + 0.8 * s.rumble.process(s.pink.process(w)).low;
                const double wh = whistle_ > 0.0 ? s.whistle.bandNormalised(w) * s.wh : 0.0;
                out[c][i] = static_cast<float>(body * s.amp + wh);
            }
        }
        for (auto& c : ch_) {
            c.band.snap();
            c.whistle.snap();
            c.rumble.snap();
        }
    }

  private:
    struct Channel {
        SmoothRandom mod;
        Svf band, whistle, rumble;
        PinkNoise pink;
        double amp = 0, ampStep = 0, wh = 0, whStep = 0;
    };
    double centreHz_, gust_, whistle_;
    SmoothRandom gustMod_;
    std::array<Channel, 2> ch_{};
    int counter_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Leaves: rustling as a Poisson stream of tiny clicks (leaf contacts) whose rate follows the
// square of a gust signal, each click ringing two broad bands; plus a breathy high-passed hiss
// in the gusts. Density scales the click rate (dry park leaves vs. a canopy in the wind).
class LeavesBed final : public BedBase {
  public:
    explicit LeavesBed(const ParamSet& p)
        : density_(p.get("density")), brightHz_(p.get("brightness_hz")), gust_(p.get("gustiness")) {
    }
    void onPrepare() override { gustMod_.configure(3.0, 1.2, fs_); }
    void onReset() noexcept override {
        gustMod_.reset(rng_);
        for (auto& c : ch_) {
            c.hi.reset();
            c.lo.reset();
            c.hiss.reset();
            c.hi.set(fs_, brightHz_, 1.4);
            c.lo.set(fs_, 0.45 * brightHz_, 2.0);
            c.hiss.set(fs_, 0.6 * brightHz_, 0.7);
        }
    }
    void process(float* left, float* right, int n) noexcept override {
        float* out[2] = {left, right};
        for (int i = 0; i < n; ++i) {
            const double g = (1.0 - gust_) * 0.5 + gust_ * gustMod_.next(rng_);
            const double p = std::min(0.5, 1800.0 * density_ * g * g / fs_);
            for (int c = 0; c < 2; ++c) {
                auto& s = ch_[c];
                double click = 0.0;
                if (rng_.uniform() < p) click = rng_.bipolar() * 6.0;
                const double x = s.hi.bandNormalised(click) + 0.6 * s.lo.bandNormalised(click);
                const double hiss = s.hiss.process(whiteNoise(rng_)).high * g * g * 0.12;
                out[c][i] = static_cast<float>(x + hiss);
            }
        }
        for (auto& c : ch_) {
            c.hi.snap();
            c.lo.snap();
            c.hiss.snap();
        }
    }

  private:
    struct Channel {
        Svf hi, lo, hiss;
    };
    double density_, brightHz_, gust_;
    SmoothRandom gustMod_;
    std::array<Channel, 2> ch_{};
};

// ---------------------------------------------------------------------------------------------
// Distant traffic: a steady low-passed brown-noise rumble plus passing cars, each a Gaussian
// swell of rumble and tyre hiss (3-7 s) that travels from one side to the other.
class TrafficBed final : public BedBase {
  public:
    explicit TrafficBed(const ParamSet& p)
        : carsPerMinute_(p.get("cars_per_minute")), cutoffHz_(p.get("cutoff_hz")),
          hiss_(p.get("hiss")) {}
    void onPrepare() override { swell_.configure(6.0, 3.0, fs_); }
    void onReset() noexcept override {
        swell_.reset(rng_);
        for (auto& c : ch_) {
            c.brown = 0.0;
            c.low.reset();
            c.tyre.reset();
            c.low.set(fs_, cutoffHz_, 0.7);
            c.tyre.set(fs_, 1400.0, 0.8);
            c.gain = 0.0;
            c.hissGain = 0.0;
        }
        for (auto& car : cars_) car.active = false;
        nextCar_ = carsPerMinute_ > 0 ? rng_.exponential(carsPerMinute_ / 60.0) * fs_ : 1e300;
        t_ = 0;
        counter_ = 0;
    }
    void process(float* left, float* right, int n) noexcept override {
        float* out[2] = {left, right};
        const double smooth = std::exp(-1.0 / (0.02 * fs_));
        for (int i = 0; i < n; ++i, ++t_) {
            if (static_cast<double>(t_) >= nextCar_) {
                startCar();
                nextCar_ += rng_.exponential(carsPerMinute_ / 60.0) * fs_;
            }
            if (counter_-- <= 0) {
                counter_ = kControlInterval;
                updateTargets();
            }
            const double base = 0.35 + 0.25 * swell_.next(rng_);
            for (int c = 0; c < 2; ++c) {
                auto& s = ch_[c];
                s.gain = s.target + smooth * (s.gain - s.target);
                s.hissGain = s.hissTarget + smooth * (s.hissGain - s.hissTarget);
                s.brown = 0.997 * s.brown + 0.08 * whiteNoise(rng_);
                const double rumble = s.low.process(s.brown).low * (base + s.gain);
                const double tyre = s.tyre.bandNormalised(whiteNoise(rng_)) * s.hissGain * hiss_;
                out[c][i] = static_cast<float>(rumble + 0.25 * tyre);
            }
        }
        for (auto& c : ch_) {
            c.low.snap();
            c.tyre.snap();
            c.brown = engine::snapToZero(c.brown);
        }
    }

  private:
    struct Car {
        bool active = false;
        double centre = 0, width = 1, peak = 0;
        bool leftToRight = true;
    };
    void startCar() noexcept {
        for (auto& car : cars_) {
            if (car.active) continue;
            car.active = true;
            car.width = rng_.uniform(1.5, 3.5) * fs_;
            car.centre = static_cast<double>(t_) + 2.5 * car.width;
            car.peak = rng_.uniform(0.4, 1.2);
            car.leftToRight = rng_.uniform() < 0.5;
            return;
        }
    }
    void updateTargets() noexcept {
        double l = 0, r = 0, hl = 0, hr = 0;
        for (auto& car : cars_) {
            if (!car.active) continue;
            const double x = (static_cast<double>(t_) - car.centre) / car.width;
            if (x > 3.0) {
                car.active = false;
                continue;
            }
            const double a = car.peak * std::exp(-x * x);
            const double pos = std::clamp(0.5 + x / 5.0, 0.0, 1.0);
            const double p = car.leftToRight ? pos : 1.0 - pos;
            const double gl = std::cos(0.5 * kPi * p), gr = std::sin(0.5 * kPi * p);
            l += a * gl;
            r += a * gr;
            hl += a * a * gl;
            hr += a * a * gr;
        }
        ch_[0].target = l;
        ch_[1].target = r;
        ch_[0].hissTarget = hl;
        ch_[1].hissTarget = hr;
    }
    struct Channel {
        double brown = 0, gain = 0, target = 0, hissGain = 0, hissTarget = 0;
        Svf low, tyre;
    };
    double carsPerMinute_, cutoffHz_, hiss_;
    SmoothRandom swell_;
    std::array<Channel, 2> ch_{};
    std::array<Car, 8> cars_{};
    double nextCar_ = 0;
    long t_ = 0;
    int counter_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Babble: N talkers, each a source-filter voice (polyBLEP sawtooth glottal source at a drifting
// pitch, two formant band-passes whose targets change per syllable) gated by syllables at
// about 4 Hz inside utterances separated by pauses; summed with fixed pans and low-passed by
// distance. Higher pitch and "excitement" (pitch leaps, louder accents) give children.
class BabbleBed final : public BedBase {
  public:
    explicit BabbleBed(const ParamSet& p)
        : talkers_(static_cast<int>(p.get("talkers"))), pitchHz_(p.get("pitch_hz")),
          syllableHz_(p.get("syllable_rate_hz")), distanceHz_(p.get("distance_hz")),
          activity_(p.get("activity")), excitement_(p.get("excitement")) {}
    void onPrepare() override {
        ft_ = 0.5 * fs_; // talkers run at half rate (their formants stay below 3 kHz)
        voices_.assign(static_cast<std::size_t>(talkers_), Talker{});
        for (auto& v : voices_) v.contour.configure(0.6, 0.25, ft_);
    }
    void onReset() noexcept override {
        for (auto& v : voices_) {
            v.saw.reset(rng_.uniform());
            v.f1.reset();
            v.f2.reset();
            v.contour.reset(rng_);
            v.pitch = pitchHz_ * rng_.uniform(0.8, 1.25);
            panGains(rng_.uniform(-0.9, 0.9), v.gl, v.gr);
            v.speaking = rng_.uniform() < activity_;
            v.left = static_cast<long>(rng_.uniform(0.2, 2.0) * ft_);
            v.sylLen = 1;
            v.sylPos = 1;
            v.f1Hz = v.f1Target = 500;
            v.f2Hz = v.f2Target = 1500;
            v.f1.set(ft_, v.f1Hz, 4.0); // a talker may start between two retunings
            v.f2.set(ft_, v.f2Hz, 6.0);
        }
        for (auto& d : dist_) {
            d.reset();
            d.set(fs_, distanceHz_, 0.6);
        }
        for (auto& d : dist2_) {
            d.reset();
            d.set(fs_, distanceHz_ * 1.3, 0.6);
        }
        counter_ = 0;
        odd_ = false;
        prevL_ = prevR_ = 0.0;
    }
    void process(float* left, float* right, int n) noexcept override {
        const double formantSmooth = std::exp(-kControlInterval / (0.03 * ft_));
        for (int i = 0; i < n; ++i) {
            // Half-rate talkers, upsampled by linear interpolation (one sample of delay); the
            // distance low-pass below removes the images.
            odd_ = !odd_;
            if (!odd_) {
                left[i] = static_cast<float>(dist2_[0].process(dist_[0].process(prevL_).low).low);
                right[i] = static_cast<float>(dist2_[1].process(dist_[1].process(prevR_).low).low);
                continue;
            }
            const bool retune = counter_-- <= 0;
            if (retune) counter_ = kControlInterval;
            double l = 0, r = 0;
            const double breath = 0.15 * whiteNoise(rng_); // shared: each talker filters it apart
            for (auto& v : voices_) {
                if (--v.left <= 0) {
                    v.speaking = !v.speaking;
                    const double utter = rng_.uniform(0.8, 4.0);
                    v.left = static_cast<long>((v.speaking ? utter
                                                           : utter * (1.0 - activity_) / activity_ *
                                                                 rng_.uniform(0.5, 1.5)) *
                                                   ft_ +
                                               1);
                }
                const double c = v.contour.next(rng_);
                if (!v.speaking) continue;
                if (++v.sylPos >= v.sylLen) newSyllable(v);
                const double u = static_cast<double>(v.sylPos) / static_cast<double>(v.sylLen);
                const double env = 4.0 * u * (1.0 - u) * v.accent; // about sin(pi u)
                if (retune) {
                    v.f1Hz = v.f1Target + formantSmooth * (v.f1Hz - v.f1Target);
                    v.f2Hz = v.f2Target + formantSmooth * (v.f2Hz - v.f2Target);
                    v.f1.set(ft_, v.f1Hz, 4.0);
                    v.f2.set(ft_, v.f2Hz, 6.0);
                }
                const double f0 = v.pitch * (0.8 + 0.4 * c) * (1.0 + v.leap * u);
                const double src = v.saw.next(f0, ft_) + breath;
                const double y = (v.f1.bandNormalised(src) + 0.6 * v.f2.bandNormalised(src)) * env;
                l += y * v.gl;
                r += y * v.gr;
            }
            const double midL = 0.5 * (prevL_ + l), midR = 0.5 * (prevR_ + r);
            prevL_ = l;
            prevR_ = r;
            l = midL;
            r = midR;
            left[i] = static_cast<float>(dist2_[0].process(dist_[0].process(l).low).low);
            right[i] = static_cast<float>(dist2_[1].process(dist_[1].process(r).low).low);
        }
        for (auto& v : voices_) {
            v.f1.snap();
            v.f2.snap();
        }
        for (auto& d : dist_) d.snap();
        for (auto& d : dist2_) d.snap();
    }

  private:
    struct Talker {
        SawOsc saw;
        Svf f1, f2;
        SmoothRandom contour;
        double pitch = 150, f1Hz = 500, f2Hz = 1500, f1Target = 500, f2Target = 1500;
        double accent = 1, leap = 0;
        float gl = 0.7f, gr = 0.7f;
        bool speaking = false;
        long left = 0, sylLen = 1, sylPos = 0;
    };
    void newSyllable(Talker& v) noexcept {
        v.sylPos = 0;
        v.sylLen = static_cast<long>(ft_ / (syllableHz_ * rng_.uniform(0.6, 1.5)));
        const double scale = std::pow(pitchHz_ / 150.0, 0.25); // smaller vocal tracts
        v.f1Target = rng_.uniform(300.0, 850.0) * scale;
        v.f2Target = rng_.uniform(900.0, 2300.0) * scale;
        const bool accent = rng_.uniform() < 0.2 + 0.5 * excitement_;
        v.accent = accent ? 1.0 + excitement_ : rng_.uniform(0.45, 0.9);
        v.leap = accent ? excitement_ * rng_.uniform(-0.2, 0.6) : 0.0;
    }
    int talkers_;
    double pitchHz_, syllableHz_, distanceHz_, activity_, excitement_, ft_ = 24000.0;
    double prevL_ = 0.0, prevR_ = 0.0;
    bool odd_ = false;
    std::vector<Talker> voices_;
    std::array<Svf, 2> dist_{}, dist2_{};
    int counter_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Distant tractor: a four-stroke diesel fires twice per revolution (4 cylinders), so the engine
// is a sawtooth buzz at rpm/30 Hz with a half-rate sub-harmonic (cylinder imbalance) and
// combustion noise gated by the firing phase, low-passed by distance; rpm drifts +-8 % and the
// tractor slowly moves around the yard (level and pan wander over tens of seconds).
class TractorBed final : public BedBase {
  public:
    explicit TractorBed(const ParamSet& p)
        : rpm_(p.get("rpm")), distanceHz_(p.get("distance_hz")), drift_(p.get("drift")) {}
    void onPrepare() override {
        rpmMod_.configure(4.0, 2.0, fs_);
        levelMod_.configure(10.0, 5.0, fs_);
        panMod_.configure(14.0, 7.0, fs_);
    }
    void onReset() noexcept override {
        rpmMod_.reset(rng_);
        levelMod_.reset(rng_);
        panMod_.reset(rng_);
        saw_.reset(rng_.uniform());
        sub_.reset(rng_.uniform());
        dist_.reset();
        dist2_.reset();
        body_.reset();
        dist_.set(fs_, distanceHz_, 0.7);
        dist2_.set(fs_, distanceHz_ * 1.5, 0.7);
        body_.set(fs_, 180.0, 2.0);
        counter_ = 0;
        gl_ = gr_ = 0.7f;
    }
    void process(float* left, float* right, int n) noexcept override {
        for (int i = 0; i < n; ++i) {
            const double firing = rpm_ / 30.0 * (1.0 + 0.16 * (rpmMod_.next(rng_) - 0.5));
            const double level = (1.0 - drift_) + drift_ * (0.25 + 0.75 * levelMod_.next(rng_));
            const double pan = 1.2 * (panMod_.next(rng_) - 0.5);
            if (counter_-- <= 0) {
                counter_ = kControlInterval;
                panGains(pan, gl_, gr_);
            }
            const double s = saw_.next(firing, fs_);
            const double gate = s > 0.5 ? 1.0 : 0.2;
            const double x = 0.6 * s + 0.4 * sub_.next(0.5 * firing, fs_) +
                             0.5 * whiteNoise(rng_) * gate + 0.8 * body_.bandNormalised(s);
            const double y = dist2_.process(dist_.process(x).low).low * level;
            left[i] = static_cast<float>(y * gl_);
            right[i] = static_cast<float>(y * gr_);
        }
        dist_.snap();
        dist2_.snap();
        body_.snap();
    }

  private:
    double rpm_, distanceHz_, drift_;
    SmoothRandom rpmMod_, levelMod_, panMod_;
    SawOsc saw_;
    SineOsc sub_;
    Svf dist_, dist2_, body_;
    int counter_ = 0;
    float gl_ = 0.7f, gr_ = 0.7f;
};

// ---------------------------------------------------------------------------------------------
// Chairlift machinery: the drive's hum (fundamental and two harmonics, slightly wavering), the
// cable's low rumble over the sheaves (pink noise below 150 Hz, decorrelated per channel) and a
// faint sheave whine. The pylon clanks are a separate event layer ("clank").
class LiftBed final : public BedBase {
  public:
    explicit LiftBed(const ParamSet& p) : humHz_(p.get("hum_hz")), squeal_(p.get("squeal")) {}
    void onPrepare() override {
        waver_.configure(1.5, 0.7, fs_);
        whine_.configure(3.0, 1.5, fs_);
    }
    void onReset() noexcept override {
        waver_.reset(rng_);
        whine_.reset(rng_);
        for (auto& o : osc_) o.reset(rng_.uniform());
        for (auto& c : ch_) {
            c.pink.reset();
            c.low.reset();
            c.low.set(fs_, 150.0, 0.7);
        }
    }
    void process(float* left, float* right, int n) noexcept override {
        float* out[2] = {left, right};
        for (int i = 0; i < n; ++i) {
            const double w = waver_.next(rng_);
            const double f = humHz_ * (1.0 + 0.01 * (w - 0.5));
            const double hum = (osc_[0].next(f, fs_) + 0.5 * osc_[1].next(2 * f, fs_) +
                                0.3 * osc_[2].next(3 * f, fs_)) *
                               (0.8 + 0.2 * w);
            const double wh =
                osc_[3].next(f * 11.3 * (1.0 + 0.02 * whine_.next(rng_)), fs_) * squeal_ * 0.08;
            for (int c = 0; c < 2; ++c) {
                const double rumble = ch_[c].low.process(ch_[c].pink.next(rng_)).low;
                out[c][i] = static_cast<float>(0.3 * hum + 1.2 * rumble + wh);
            }
        }
        for (auto& c : ch_) c.low.snap();
    }

  private:
    struct Channel {
        PinkNoise pink;
        Svf low;
    };
    double humHz_, squeal_;
    SmoothRandom waver_, whine_;
    std::array<SineOsc, 4> osc_{};
    std::array<Channel, 2> ch_{};
};

// The factories that Procedural.h declares (constant-initialised: usable at any time).
template <class Generator>
std::unique_ptr<BedGenerator> makeBed(const ParamSet& p) {
    return std::make_unique<Generator>(p);
}

} // namespace

constinit const BedFactory makeSea = makeBed<SeaBed>;
constinit const BedFactory makeWind = makeBed<WindBed>;
constinit const BedFactory makeLeaves = makeBed<LeavesBed>;
constinit const BedFactory makeTraffic = makeBed<TrafficBed>;
constinit const BedFactory makeBabble = makeBed<BabbleBed>;
constinit const BedFactory makeTractor = makeBed<TractorBed>;
constinit const BedFactory makeLift = makeBed<LiftBed>;

} // namespace underfoot::soundscapes::procedural
