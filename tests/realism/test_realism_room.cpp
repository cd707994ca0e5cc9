// SPDX-License-Identifier: GPL-3.0-or-later
// A surface rendered in a room (a preset with [reverb]) is compared with the recordings heard
// through the same room (realism/Compare.h: throughRoom, roomOfSurface): the mix is the
// renderer's (dry + wet convolution; exact against the renders of wood and wood with reverb),
// and a recording put through the room is at distance ~0 from
// the same recording compared in that room, while the dry comparison puts the room's whole
// effect into the distance.
#include "engine/render/FootstepScene.h"
#include "engine/reverb/Convolver.h"
#include "realism/Compare.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <vector>

using namespace underfoot;
using namespace underfoot::realism;
namespace fs = std::filesystem;

namespace {

engine::ReverbSpec woodenRoom() {
    engine::ReverbSpec r;
    r.impulseResponse = "wooden_room";
    r.wetDb = -6.0;
    r.dryDb = 0.0;
    return r;
}

// Eight decaying noise bursts (footstep-like: 4 ms rise, 40 ms decay), 0.6 s apart, mono.
engine::AudioBuffer steps(double fs, unsigned seed) {
    engine::AudioBuffer b;
    b.sampleRateHz = fs;
    b.channels = 1;
    b.samples.assign(static_cast<std::size_t>(5.2 * fs), 0.0f);
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.2);
    for (int k = 0; k < 8; ++k) {
        const auto at = static_cast<std::size_t>((0.2 + 0.6 * k) * fs);
        for (std::size_t i = 0; i < static_cast<std::size_t>(0.3 * fs); ++i) {
            const double t = double(i) / fs;
            const double env = std::min(1.0, t / 0.004) * std::exp(-t / 0.04);
            b.samples[at + i] = static_cast<float>(env * noise(rng));
        }
    }
    return b;
}

} // namespace

TEST(RealismRoom, ThroughRoomIsTheRenderersDryPlusWetMix) {
    engine::AudioBuffer impulse;
    impulse.sampleRateHz = 48000;
    impulse.channels = 1;
    impulse.samples.assign(100, 0.0f);
    impulse.samples[0] = 1.0f;
    const auto room = woodenRoom();
    const auto out = throughRoom(impulse, room);

    engine::Convolver c;
    c.prepare(engine::readAudioFile(engine::findImpulseResponse(room.impulseResponse)), 48000, 64);
    const auto& ir = c.impulseResponse(); // interleaved stereo at 48 kHz
    ASSERT_EQ(out.channels, 2);
    ASSERT_EQ(out.frames(), impulse.frames() + c.impulseLength()); // the tail is kept
    // The room is fed the voices' sum: the channel mean / the pan law (realism/Compare.h).
    const double panLaw = std::cos(engine::SceneOptions{}.panSpread * std::numbers::pi / 4);
    const double wet = std::pow(10.0, room.wetDb / 20.0) / panLaw;
    for (std::size_t f = 0; f < c.impulseLength(); f += 97)
        for (int ch = 0; ch < 2; ++ch) {
            const double expected = (f == 0 ? 1.0 : 0.0) + wet * ir.at(f, ch);
            ASSERT_NEAR(out.at(f, ch), expected, 1e-5) << "frame " << f << " channel " << ch;
        }
}

TEST(RealismRoom, ARecordingInTheRoomMatchesItselfComparedInThatRoom) {
    const auto dir = fs::temp_directory_path() / "underfoot_realism_room";
    fs::create_directories(dir);
    // A "recording" at 44.1 kHz (the room's impulse response is resampled to its rate).
    const auto dry = steps(44100, 11);
    Recording r;
    r.path = (dir / "steps.wav").string();
    r.file = "steps.wav";
    r.source = "test";
    r.material = "wood";
    engine::writeAudioFile(r.path, dry, engine::SampleFormat::Float32);

    const auto room = woodenRoom();
    const auto heardInRoom = throughRoom(dry, room); // what a render in that room would be
    const auto inRoom = compareAudio("wood_reverb", heardInRoom, {r}, room);
    const auto asRecorded = compareAudio("wood_reverb", heardInRoom, {r});
    std::printf("distance in the room %.3f, to the dry recording %.3f\n",
                inRoom.comparison.distance, asRecorded.comparison.distance);
    ASSERT_TRUE(inRoom.room.has_value());
    EXPECT_EQ(inRoom.room->impulseResponse, "wooden_room");
    EXPECT_FALSE(asRecorded.room.has_value());
    EXPECT_EQ(inRoom.syntheticSteps.size(), inRoom.realSteps.size());
    EXPECT_LT(inRoom.comparison.distance, 0.05);
    // The dry comparison charges the room to the sound: decay, active time, crest all move.
    EXPECT_GT(asRecorded.comparison.distance, inRoom.comparison.distance + 0.2);
    fs::remove_all(dir);
}

TEST(RealismRoom, TheWoodRenderThroughItsRoomIsTheWoodWithReverbRender) {
    // Wood with reverb is wood's layers in the wooden room. The analysis hears the channel mean,
    // so the channel mean of the wood render through throughRoom() must be that of the wood with
    // reverb render, sample for sample (float rounding apart; without the pan-law factor the
    // room would be 0.24 dB too quiet and this fails at about 1e-2 of the peak).
    RenderSpec spec;
    spec.seconds = 3;
    const auto wood = renderForComparison("wood", spec);
    const auto inRoom = renderForComparison("wood_reverb", spec);
    const auto mine = throughRoom(wood, *roomOfSurface("wood_reverb"));
    ASSERT_EQ(inRoom.channels, 2);
    ASSERT_GE(mine.frames(), inRoom.frames());
    double peak = 0, worst = 0;
    for (std::size_t f = 0; f < inRoom.frames(); ++f) {
        const double a = 0.5 * (double(inRoom.at(f, 0)) + double(inRoom.at(f, 1)));
        const double b = 0.5 * (double(mine.at(f, 0)) + double(mine.at(f, 1)));
        peak = std::max(peak, std::fabs(a));
        worst = std::max(worst, std::fabs(a - b));
    }
    std::printf("channel mean: peak %.6f, worst difference %.3g\n", peak, worst);
    EXPECT_LT(worst, 1e-4 * peak);
}

TEST(RealismRoom, TheRoomOfASurfaceIsItsPresetsReverb) {
    const auto room = roomOfSurface("wood_reverb");
    ASSERT_TRUE(room.has_value());
    EXPECT_EQ(room->impulseResponse, "wooden_room");
    EXPECT_DOUBLE_EQ(room->wetDb, -6.0);
    EXPECT_FALSE(roomOfSurface("wood").has_value());
}
