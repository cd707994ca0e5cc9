// SPDX-License-Identifier: GPL-3.0-or-later
// Pins the samples of every procedural generator: a stored seed must replay exactly what a
// participant heard, so a refactoring of the generators may not change one bit. Each generator
// renders a short stretch with its default parameters and the FNV-1a hash of the float bit
// patterns is compared with the value recorded before the generators were last restructured.
#include "engine/dsp/Random.h"
#include "soundscapes/Generators.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <vector>

using namespace underfoot;
using namespace underfoot::soundscapes;

namespace {

constexpr double kFs = 48000.0;
constexpr int kBlock = 256;
constexpr std::uint64_t kSeed = 20261206;

struct Fnv1a {
    std::uint64_t h = 14695981039346656037ull;
    void add(float x) {
        std::uint32_t bits = 0;
        std::memcpy(&bits, &x, sizeof bits);
        for (int b = 0; b < 4; ++b) {
            h ^= (bits >> (8 * b)) & 0xffu;
            h *= 1099511628211ull;
        }
    }
};

// Beds: 0.5 s of both channels. Event voices: three events in a row, each to its end.
std::uint64_t renderHash(const GeneratorInfo& g) {
    Fnv1a hash;
    std::vector<float> l(kBlock), r(kBlock);
    const ParamSet defaults;
    if (g.kind == LayerKind::Bed) {
        auto bed = makeBedGenerator(g.name, defaults);
        bed->prepare({kFs, kBlock});
        bed->reset(kSeed);
        for (int t = 0; t < static_cast<int>(0.5 * kFs); t += kBlock) {
            bed->process(l.data(), r.data(), kBlock);
            for (int i = 0; i < kBlock; ++i) {
                hash.add(l[i]);
                hash.add(r[i]);
            }
        }
    } else {
        auto voice = makeEventVoice(g.name, defaults);
        voice->prepare({kFs, kBlock});
        voice->reset(kSeed, kSeed + 1);
        engine::Random rng(kSeed);
        for (int e = 0; e < 3; ++e) {
            voice->start(rng);
            for (int got = kBlock; got == kBlock;) {
                got = voice->process(l.data(), kBlock);
                for (int i = 0; i < got; ++i) hash.add(l[i]);
            }
        }
    }
    return hash.h;
}

// Recorded with this test on commit 9ed8332 (before the generators shared their code): run
// `build/tests/soundscapes/test_soundscapes --gtest_filter='SoundscapeSamples.*'`; a mismatch
// prints the hash it rendered.
const std::map<std::string, std::uint64_t>& pinned() {
    static const std::map<std::string, std::uint64_t> values{
        {"babble", 0xc36858acf4d59a84ull},   {"clank", 0x8d75b2ae5d151fe1ull},
        {"cow", 0xaddc80f5e8d6552bull},      {"cuckoo", 0x446da12dde363948ull},
        {"dog", 0x3856a5b8992e2becull},      {"gull", 0xb40ebf859729d54cull},
        {"hen", 0x56b2b0730da35d68ull},      {"leaves", 0x64812ceaca2e5750ull},
        {"lift", 0x7aea4f0c76f8c510ull},     {"rooster", 0x18a52ddbf785f1b4ull},
        {"scrape", 0x2a9ee64c993be10aull},   {"sea", 0x9a97cb8e1d437506ull},
        {"shout", 0x9e3d4386f6b4d80eull},    {"skitter", 0x9bb368c334389836ull},
        {"songbird", 0xdfbc4eb05d9afad5ull}, {"swish", 0xb7892e731247ebd2ull},
        {"tractor", 0x4c9fa5063228b474ull},  {"traffic", 0xfd92e2d99ecbc49ull},
        {"wind", 0x39fb018573b7a1d3ull},     {"woodpecker", 0x85302a4bc43cc10dull},
    };
    return values;
}

} // namespace

TEST(SoundscapeSamples, EveryGeneratorRendersTheSamplesItDidBefore) {
    EXPECT_EQ(pinned().size(), generatorCatalogue().size())
        << "a generator was added or removed: pin its samples here";
    for (const auto& g : generatorCatalogue()) {
        const auto it = pinned().find(g.name);
        ASSERT_NE(it, pinned().end()) << "no pinned samples for generator '" << g.name << "'";
        const std::uint64_t h = renderHash(g);
        EXPECT_EQ(h, it->second) << g.name << " rendered 0x" << std::hex << h << "ull";
    }
}
