// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/surfaces/LiquidLayers.h"

#include "engine/dsp/Envelope.h"
#include "engine/surfaces/LoadInput.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace underfoot::engine {

namespace {
constexpr double kTailSeconds = 0.1;
constexpr double kDerivativeRefKnPerS = 10.0;
constexpr double kQuiet = 1e-6;   // envelopes below this are silent
constexpr double kOffDb = -120.0; // noise levels at or below this are off
constexpr double kWakeEnd = 1e-3; // the wake envelope ends 60 dB below its nominal start

} // namespace

BubblesLayer::BubblesLayer(const BubbleStreamParameters& stream, const BubblesControl& control,
                           const AccuracyOptions& options)
    : control_(control), maxEventsPerSecond_(options.maxEventsPerSecond) {
    stream_.configure(stream);
    gain_ = dbToGain(control.gainDb);
    splashGain_ = control.splashNoiseDb <= kOffDb ? 0.0 : dbToGain(control.splashNoiseDb);
    sloshGain_ = control.sloshDb <= kOffDb ? 0.0 : dbToGain(control.sloshDb);
}

void BubblesLayer::prepare(const ProcessSpec& spec) {
    prepareLoad(spec, control_.derivativeMs, control_.contactThresholdN, kTailSeconds);
    stream_.prepare(sampleRateHz_, maxEventsPerSecond_);
    splashDecayG_ = onePoleCoefficientTau(control_.splashDecayMs * 1e-3, sampleRateHz_);
    splashRiseG_ = control_.splashRiseMs > 0
                       ? onePoleCoefficientTau(control_.splashRiseMs * 1e-3, sampleRateHz_)
                       : 0.0;
    wakeG_ = onePoleCoefficientTau(control_.wakeMs * 1e-3, sampleRateHz_);
    motionG_ = onePoleCoefficientTau(0.03, sampleRateHz_); // 30 ms: the water follows the foot
    settling_.prepare(control_.settling, sampleRateHz_);
    const double guard = 0.45 * sampleRateHz_;
    splashFilter_.setCoefficients(
        BiquadCoefficients::bandpass(sampleRateHz_, std::min(control_.splashHz, guard), 0.8));
    sloshFilter_.setCoefficients(
        BiquadCoefficients::bandpass(sampleRateHz_, std::min(control_.sloshHz, guard), 0.9));
    splashSamples_ = static_cast<int>(control_.splashMs * 1e-3 * sampleRateHz_);
    const auto block = static_cast<std::size_t>(std::max(1, spec.maxBlockSize));
    rate_.assign(block, 0.0f);
    scale_.assign(block, 1.0f);
    buffer_.assign(block, 0.0f);
    reset(0);
}

void BubblesLayer::reset(std::uint64_t seed) noexcept {
    stream_.reset(Random::deriveSeed(seed, 0));
    noise_.setSeed(Random::deriveSeed(seed, 1));
    splashFilter_.reset();
    sloshFilter_.reset();
    resetLoad();
    inContact_ = false;
    settling_.reset();
    contactSamples_ = 0;
    releasePeak_ = 0.0;
    splashEnv_ = wakeEnv_ = motionEnv_ = 0.0;
}

bool BubblesLayer::processAwake(const float* grf, float* out, int n) noexcept {
    const double threshold = control_.contactThresholdN;
    bool contactSeen = false;
    float* buffer = buffer_.data();
    for (int i = 0; i < n; ++i) {
        const double f = sanitizeForce(grf[i]);
        const bool jump = trackLoad(f); // a cut: the foot is already in the water
        const bool contact = f > threshold;
        if (contact && !inContact_) {
            inContact_ = true;
            contactSamples_ = jump ? splashSamples_ : 0; // no landing, no splash
            releasePeak_ = 0.0;
        } else if (!contact && inContact_) {
            inContact_ = false;
            settling_.reset();
            if (control_.wakeMs > 0)
                wakeEnv_ =
                    std::max(wakeEnv_, std::clamp(releasePeak_ / kDerivativeRefKnPerS, 0.25, 2.0));
        }
        const double rise = std::max(derivative_, 0.0);
        const double speed = std::fabs(derivative_);
        double rate = control_.wakeBubblesHz * wakeEnv_;
        double splashDrive = 0.0;
        double motionDrive = 0.0;
        if (contact) {
            contactSeen = true;
            ++contactSamples_;
            releasePeak_ = std::max(releasePeak_, -derivative_);
            // A leg held still: the water around it calms (LoadSettling; exactly 1 while
            // wading), so the motion's bubbles and slosh fade out.
            const double settle = settling_.inContact(derivative_);
            rate += control_.bubblesPerKn * speed * settle;
            if (contactSamples_ <= splashSamples_) {
                rate += control_.splashBubblesPerKn * rise;
                splashDrive = rise / kDerivativeRefKnPerS;
            }
            motionDrive = speed / kDerivativeRefKnPerS * settle;
        }
        rate_[static_cast<std::size_t>(i)] = static_cast<float>(rate);
        wakeEnv_ *= wakeG_;
        if (wakeEnv_ < kWakeEnd) wakeEnv_ = 0.0; // 60 dB down: the wake is over
        if (splashDrive <= splashEnv_)
            splashEnv_ *= splashDecayG_;
        else if (splashRiseG_ > 0) // the splash develops: rise towards the drive
            splashEnv_ = splashDrive + splashRiseG_ * (splashEnv_ - splashDrive);
        else
            splashEnv_ = splashDrive;
        motionEnv_ = motionDrive + motionG_ * (motionEnv_ - motionDrive);
        const double splashAmp = splashGain_ * splashEnv_;
        const double sloshAmp = sloshGain_ * (motionEnv_ + wakeEnv_);
        double noise = 0.0;
        if (splashAmp > kQuiet || sloshAmp > kQuiet) {
            const double w = noise_.bipolar();
            noise = splashAmp * splashFilter_.processSample(w) +
                    sloshAmp * sloshFilter_.processSample(w);
        }
        buffer[i] = static_cast<float>(noise);
    }
    stream_.process(rate_.data(), scale_.data(), buffer, n);
    const float gain = static_cast<float>(gain_);
    for (int i = 0; i < n; ++i) out[i] += gain * buffer[i];
    return contactSeen;
}

bool BubblesLayer::settleTail() noexcept {
    wakeEnv_ = snapToZero(wakeEnv_);
    splashEnv_ = snapToZero(splashEnv_);
    motionEnv_ = snapToZero(motionEnv_);
    return wakeEnv_ < kQuiet && splashEnv_ < kQuiet && motionEnv_ < kQuiet && stream_.idle();
}

void BubblesLayer::fallAsleep() noexcept {
    splashFilter_.reset();
    sloshFilter_.reset();
    wakeEnv_ = splashEnv_ = motionEnv_ = 0.0;
}

std::unique_ptr<SurfaceLayer> makeBubblesLayer(PresetReader& r, const AccuracyOptions& options) {
    BubbleStreamParameters s;
    BubblesControl c;
    c.gainDb = r.number("gain_db", 0.0, -60.0, 40.0, "dB", "level of this layer");
    std::tie(s.radiusMinM, s.radiusMaxM) =
        orderedPair(r.number("radius_min_mm", 0.5, 0.1, 30.0, "mm",
                             "smallest bubble radius (f0 = 3 / r: 0.5 mm rings at 6 kHz)", true),
                    r.number("radius_max_mm", 5.0, 0.1, 30.0, "mm",
                             "largest bubble radius (5 mm rings at 600 Hz)", true));
    s.radiusMinM *= 1e-3;
    s.radiusMaxM *= 1e-3;
    s.radiusExponent = r.number("radius_exponent", -2.0, -4.0, 1.0, "",
                                "radii drawn from p(r) ~ r^radius_exponent");
    s.xi = r.number("xi", 0.1, 0.0, 0.5, "", "pitch rise: f(t) = f0 (1 + xi d t)");
    s.depthMin = r.number("depth_min", 0.3, 0.05, 1.0, "",
                          "depth factors of the bubbles drawn uniformly in [depth_min, 1]");
    s.voices = r.integer("voices", 48, 1, 256, "simultaneous bubbles");
    s.maxRateHz = r.number("max_rate_hz", 3000.0, 1.0, 20000.0, "bubbles/s",
                           "this layer's cap on the bubble rate", true);
    c.bubblesPerKn = r.number("bubbles_per_kn", 0.0, 0.0, 5000.0, "bubbles/kN",
                              "bubbles per kN of load change while the foot is in the water");
    c.splashBubblesPerKn = r.number("splash_bubbles_per_kn", 0.0, 0.0, 20000.0, "bubbles/kN",
                                    "bubbles per kN of load taken on while the foot lands");
    c.splashMs =
        r.number("splash_ms", 60.0, 5.0, 500.0, "ms", "how long the landing splashes", true);
    c.splashNoiseDb = r.number("splash_noise_db", -120.0, -120.0, 20.0, "dB",
                               "level of the splash noise at 10 kN/s of landing (-120: off)");
    c.splashHz = r.number("splash_hz", 3000.0, 100.0, 16000.0, "Hz",
                          "centre of the splash noise band", true);
    c.splashDecayMs = r.number("splash_decay_ms", 40.0, 2.0, 1000.0, "ms",
                               "decay time constant of the splash noise", true);
    c.splashRiseMs =
        r.number("splash_rise_ms", 0.0, 0.0, 500.0, "ms",
                 "rise time constant of the splash noise towards the landing's drive: the splash "
                 "develops after the foot lands (0: at once)");
    c.wakeMs = r.number("wake_ms", 0.0, 0.0, 2000.0, "ms",
                        "decay time constant of the motion after the foot leaves (0: none)");
    c.wakeBubblesHz = r.number("wake_bubbles_hz", 0.0, 0.0, 5000.0, "bubbles/s",
                               "bubble rate at the start of the wake");
    c.sloshDb = r.number("slosh_db", -120.0, -120.0, 20.0, "dB",
                         "level of the displaced-water noise at 10 kN/s of motion (-120: off)");
    c.sloshHz =
        r.number("slosh_hz", 400.0, 50.0, 5000.0, "Hz", "centre of the slosh noise band", true);
    c.derivativeMs =
        r.number("derivative_ms", 5.0, 0.5, 50.0, "ms", "smoothing time constant of dF/dt", true);
    c.contactThresholdN = r.number("contact_threshold_n", 5.0, 0.5, 100.0, "N",
                                   "load below which the foot is out of the water", true);
    c.settling = LoadSettling::read(r);
    return std::make_unique<BubblesLayer>(s, c, options);
}

} // namespace underfoot::engine
