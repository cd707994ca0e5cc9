// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/dsp/Biquad.h"
#include "engine/dsp/Random.h"
#include "engine/reverb/RoomModel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace underfoot::engine;

namespace {

// Octave band of one channel: 3rd-order Butterworth high-pass at fc / sqrt 2 and low-pass at
// fc sqrt 2 (an independent filter, not the generator's FFT crossovers).
std::vector<float> octaveBand(const std::vector<float>& x, double fs, double fc) {
    Butterworth bp;
    bp.design(FilterType::Bandpass, 3, fs, fc / std::sqrt(2.0),
              std::min(fc * std::sqrt(2.0), 0.45 * fs));
    std::vector<float> y = x;
    bp.process(y.data(), static_cast<int>(y.size()));
    return y;
}

} // namespace

TEST(RoomModel, SchroederMeasurementOfAnExactExponentialDecay) {
    // Noise with an exact 1.3 s decay: the measured T30 and T20 are 1.3 s within 2 %.
    Random r(1);
    const double fs = 48000, t60 = 1.3;
    std::vector<float> ir(static_cast<std::size_t>(1.5 * t60 * fs));
    for (std::size_t i = 0; i < ir.size(); ++i)
        ir[i] = static_cast<float>(r.gaussian() * std::exp(-6.9078 * double(i) / fs / t60));
    EXPECT_NEAR(schroederT60Seconds(ir, fs), t60, 0.02 * t60);
    EXPECT_NEAR(schroederT60Seconds(ir, fs, -5, -25), t60, 0.02 * t60);
    const auto edc = energyDecayCurveDb(ir);
    EXPECT_DOUBLE_EQ(edc[0], 0.0);
    EXPECT_THROW(schroederT60Seconds(std::vector<float>(100, 0.0f), fs), std::invalid_argument);
}

TEST(RoomModel, MeasuredT60MatchesTheRequestedT60PerOctaveBand) {
    for (const auto& name : roomPresetNames()) {
        const RoomSpec room = roomPreset(name);
        for (std::uint64_t seed : {1u, 2u}) {
            RoomIrOptions o;
            o.seed = seed;
            const AudioBuffer ir = generateRoomImpulseResponse(room, o);
            // ISO 3382-1 averages over receiver positions: the energy of both ears is summed
            // (the per-ear T30 of the 125 Hz band scatters by up to +-10 % across seeds).
            for (int b = 0; b < kOctaveBandCount; ++b) {
                const double fc = kOctaveBandCentersHz[static_cast<std::size_t>(b)];
                const double want = room.t60Seconds[static_cast<std::size_t>(b)];
                const auto l = octaveBand(ir.channel(0), 48000, fc);
                const auto r = octaveBand(ir.channel(1), 48000, fc);
                std::vector<float> both(l.size());
                for (std::size_t i = 0; i < l.size(); ++i) both[i] = std::hypot(l[i], r[i]);
                const double got = schroederT60Seconds(both, 48000);
                EXPECT_NEAR(got / want, 1.0, 0.10)
                    << name << " seed " << seed << " " << fc << " Hz: measured " << got
                    << " s, requested " << want << " s";
                // Each ear alone stays within 15 %.
                EXPECT_NEAR(schroederT60Seconds(l, 48000) / want, 1.0, 0.15) << name << " " << fc;
                EXPECT_NEAR(schroederT60Seconds(r, 48000) / want, 1.0, 0.15) << name << " " << fc;
            }
        }
    }
}

TEST(RoomModel, StructureDirectSoundTailAndStereo) {
    const RoomSpec room = roomPreset("wooden_room");
    EXPECT_NEAR(room.midT60Seconds(), 0.8, 1e-12);
    const AudioBuffer ir = generateRoomImpulseResponse(room);
    EXPECT_EQ(ir.sampleRateHz, 48000);
    EXPECT_EQ(ir.channels, 2);
    EXPECT_EQ(ir.frames(), static_cast<std::size_t>(std::llround(1.1 * 0.80 * 48000)));
    // Direct sound at sample 0 with amplitude 0.5 (zero pre-delay) in both ears (the source is
    // centred between them).
    // (+ the sinc side lobe of the floor reflection, 2.8 samples later).
    EXPECT_NEAR(ir.at(0, 0), 0.5, 0.05);
    EXPECT_NEAR(ir.at(0, 1), 0.5, 0.05);
    // The floor reflection: path via the floor image of a source 1 cm above the floor.
    const double d0 = std::hypot(0.2, 0.09, 1.59), d1 = std::hypot(0.2, 0.09, 1.61);
    const auto floorSample = static_cast<std::size_t>(std::lround((d1 - d0) / 343.0 * 48000));
    double around = 0;
    for (std::size_t i = floorSample - 1; i <= floorSample + 1; ++i)
        around = std::max(around, double(std::fabs(ir.at(i, 0))));
    EXPECT_GT(around, 0.3); // beta^1 x d0/d1 x 0.5 ~ 0.47, spread by the fractional delay
    // Peak within PCM range.
    float peak = 0;
    for (float v : ir.samples) peak = std::max(peak, std::fabs(v));
    EXPECT_LE(peak, 0.99f);
    // The two ears' late tails are decorrelated (independent noise): |r| < 0.1 after 100 ms.
    double sxy = 0, sxx = 0, syy = 0;
    for (std::size_t i = 4800; i < ir.frames(); ++i) {
        sxy += double(ir.at(i, 0)) * ir.at(i, 1);
        sxx += double(ir.at(i, 0)) * ir.at(i, 0);
        syy += double(ir.at(i, 1)) * ir.at(i, 1);
    }
    EXPECT_LT(std::fabs(sxy / std::sqrt(sxx * syy)), 0.1);
    // No step where the tail takes over: the energy in 5 ms windows around the mixing time
    // changes by less than 6 dB from one window to the next (reflections are sparse before).
    const double tMix = room.mixingTimeSeconds();
    auto energy = [&](double t0) {
        double e = 0;
        for (auto i = static_cast<std::size_t>(t0 * 48000);
             i < static_cast<std::size_t>((t0 + 0.01) * 48000); ++i)
            e += double(ir.at(i, 0)) * ir.at(i, 0) + double(ir.at(i, 1)) * ir.at(i, 1);
        return e;
    };
    const double before = energy(tMix - 0.01), after = energy(1.5 * tMix);
    EXPECT_LT(std::fabs(10 * std::log10(after / before)), 6.0) << before << " " << after;
}

TEST(RoomModel, SeededAndValidated) {
    const RoomSpec room = roomPreset("small_room");
    RoomIrOptions o;
    o.seed = 5;
    const AudioBuffer a = generateRoomImpulseResponse(room, o),
                      b = generateRoomImpulseResponse(room, o);
    EXPECT_EQ(a.samples, b.samples);
    o.seed = 6;
    EXPECT_NE(generateRoomImpulseResponse(room, o).samples, a.samples);
    o.channels = 1;
    o.lengthSeconds = 0.25;
    o.sampleRateHz = 44100;
    const AudioBuffer mono = generateRoomImpulseResponse(room, o);
    EXPECT_EQ(mono.channels, 1);
    EXPECT_EQ(mono.frames(), 11025u);
    o.channels = 3;
    EXPECT_THROW(generateRoomImpulseResponse(room, o), std::invalid_argument);
    try {
        roomPreset("cathedral");
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("wooden_room"), std::string::npos);
    }
    RoomSpec bad = room;
    bad.t60Seconds[3] = std::nan("");
    EXPECT_THROW(bad.validate(), std::invalid_argument);
    bad = roomPreset("hall");
    bad.t60Seconds[3] = 0.1; // Eyring absorption 0.992 in a 7200 m^3 hall
    EXPECT_THROW(bad.validate(), std::invalid_argument);
    bad = room;
    bad.sourceM.x = 10;
    EXPECT_THROW(bad.validate(), std::invalid_argument);
}
