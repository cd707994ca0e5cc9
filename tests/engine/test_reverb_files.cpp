// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/reverb/ImpulseResponses.h"
#include "engine/reverb/RoomModel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

using namespace underfoot::engine;

TEST(ImpulseResponses, ResolvesShippedNamesAndPaths) {
    const auto names = availableImpulseResponses();
    for (const char* required : {"hall", "wooden_room"})
        EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
    const std::string path = findImpulseResponse("wooden_room");
    EXPECT_EQ(std::filesystem::path(path).filename(), "wooden_room.wav");
    EXPECT_TRUE(std::filesystem::is_regular_file(path));
    EXPECT_EQ(findImpulseResponse(path), path); // a path is taken as is
    try {
        findImpulseResponse("cathedral");
        FAIL();
    } catch (const FileError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("\"cathedral\" not found"), std::string::npos) << msg;
        EXPECT_NE(msg.find("hall"), std::string::npos) << msg;
        EXPECT_NE(msg.find("wooden_room"), std::string::npos) << msg;
    }
    EXPECT_THROW(findImpulseResponse("/no/such/file.wav"), FileError);
    EXPECT_THROW(findImpulseResponse(""), FileError);
}

TEST(ImpulseResponses, ShippedFilesAreWhatTheDocumentedCommandGenerates) {
    // engine/data/ir/README.md: `underfoot ir generate --room NAME --seed 1` at 48 kHz, 24 bit.
    for (const char* name : {"wooden_room", "hall", "small_room"}) {
        const AudioBuffer shipped = readAudioFile(findImpulseResponse(name));
        EXPECT_EQ(shipped.sampleRateHz, 48000);
        EXPECT_EQ(shipped.channels, 2);
        EXPECT_LT(std::filesystem::file_size(findImpulseResponse(name)), 1'000'000u);
        RoomIrOptions o;
        o.seed = 1;
        const AudioBuffer fresh = generateRoomImpulseResponse(roomPreset(name), o);
        ASSERT_EQ(fresh.samples.size(), shipped.samples.size()) << name;
        double err = 0;
        for (std::size_t i = 0; i < fresh.samples.size(); ++i)
            err = std::max(err, std::fabs(double(fresh.samples[i]) - shipped.samples[i]));
        EXPECT_LE(err, 1.0 / 8388608.0) << name; // 24-bit quantisation step
    }
}
