// SPDX-License-Identifier: GPL-3.0-or-later
// The grains layer's load memory (felicity_ratio, engine/surfaces/GranularLayers.h): with ratio
// R the load-rise terms count only while the load is at least R x the highest load of the
// contact so far (a brittle crust breaks only under a load it has not carried yet: the Kaiser
// effect). 0, the default, lets every rise count, and no bundled preset but frozen snow sets it.
#include "engine/surfaces/GranularLayers.h"
#include "engine/surfaces/Surface.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

using namespace underfoot::engine;

namespace {
constexpr double kFs = 48000.0;

// A GRF of straight ramps between (time s, load N) points.
std::vector<float> ramps(const std::vector<std::pair<double, double>>& points) {
    std::vector<float> g;
    for (std::size_t k = 1; k < points.size(); ++k) {
        const auto [t0, f0] = points[k - 1];
        const auto [t1, f1] = points[k];
        const auto n = static_cast<int>((t1 - t0) * kFs);
        for (int i = 0; i < n; ++i)
            g.push_back(static_cast<float>(f0 + (f1 - f0) * double(i) / double(n)));
    }
    return g;
}

// One contact: loaded to 800 N, unloaded to 400 N, reloaded to 700 N (below the peak), then on
// to 1000 N (beyond it) and released; after 0.2 s of no contact, a second contact to 600 N.
const std::vector<std::pair<double, double>> kPoints = {
    {0.0, 0.0},     {0.10, 800.0}, {0.20, 400.0}, {0.30, 700.0}, {0.40, 700.0},
    {0.50, 1000.0}, {0.60, 0.0},   {0.80, 0.0},   {0.90, 600.0}, {1.00, 0.0}};

struct Counts {
    int firstLoad = 0, reload = 0, beyondPeak = 0, secondContact = 0;
};

Counts eventsByPhase(double felicityRatio, double onsetEnergy = 0.0) {
    AggregateParameters m;
    m.gamma = -1.0;
    m.energyMin = 0.1;
    m.voices = 64;
    GrainsControl c;
    c.eventsPerKnRise = 400; // events per kN of load increase
    c.riseEnergy = 2.0;
    c.felicityRatio = felicityRatio;
    c.onsetEnergy = onsetEnergy;
    c.derivativeMs = 0.5;
    GrainsLayer layer(m, c, AccuracyOptions{});
    layer.prepare({kFs, 256});
    layer.reset(3);
    Counts counts;
    layer.model().setEventObserver(
        [](void* u, const AggregateEvent& e) {
            auto* n = static_cast<Counts*>(u);
            const double t = double(e.sample) / kFs;
            if (t < 0.105)
                ++n->firstLoad;
            else if (t >= 0.2 && t < 0.405)
                ++n->reload;
            else if (t >= 0.405 && t < 0.505)
                ++n->beyondPeak;
            else if (t >= 0.8)
                ++n->secondContact;
        },
        &counts);
    const auto grf = ramps(kPoints);
    std::vector<float> out(grf.size(), 0.0f);
    layer.process(grf.data(), out.data(), static_cast<int>(grf.size()));
    return counts;
}
} // namespace

TEST(GrainsLoadMemory, WithoutMemoryEveryLoadRiseBreaks) {
    const auto n = eventsByPhase(0.0);
    // 0.8, 0.3, 0.3 and 0.6 kN of rise at 400 events/kN: about 320, 120, 120 and 240 events.
    EXPECT_GT(n.firstLoad, 240);
    EXPECT_GT(n.reload, 80);
    EXPECT_GT(n.beyondPeak, 80);
    EXPECT_GT(n.secondContact, 180);
}

TEST(GrainsLoadMemory, AStrictMemoryBreaksOnlyBeyondTheContactsPeak) {
    const auto n = eventsByPhase(1.0);
    EXPECT_GT(n.firstLoad, 240); // the first loading breaks as before
    EXPECT_EQ(n.reload, 0);      // reloading below the 800 N already carried breaks nothing
    // 800 -> 1000 N is new load: about 0.2 kN x 400 events (the 700 -> 800 N part is silent).
    EXPECT_GT(n.beyondPeak, 40);
    EXPECT_LT(n.beyondPeak, 130);
    EXPECT_GT(n.secondContact, 180); // the memory is cleared when the foot leaves
}

TEST(GrainsLoadMemory, ALowerRatioBreaksAgainBeforeTheOldPeak) {
    // Felicity ratio 0.8: reloading breaks again from 0.8 x 800 = 640 N on.
    const auto strict = eventsByPhase(1.0);
    const auto felicity = eventsByPhase(0.8);
    EXPECT_GT(felicity.reload, 10);
    EXPECT_LT(felicity.reload, eventsByPhase(0.0).reload);
    EXPECT_GT(felicity.beyondPeak, strict.beyondPeak);
}

TEST(GrainsLoadMemory, TheHeelsOnsetEventStillFires) {
    // The onset event (the heel's thump) is not a load-rise term: it fires with or without memory.
    AggregateParameters m;
    GrainsControl c;
    c.onsetEnergy = 1.0;
    c.felicityRatio = 1.0;
    GrainsLayer layer(m, c, AccuracyOptions{});
    layer.prepare({kFs, 256});
    layer.reset(1);
    const auto grf = ramps(kPoints);
    std::vector<float> out(grf.size(), 0.0f);
    layer.process(grf.data(), out.data(), static_cast<int>(grf.size()));
    EXPECT_EQ(layer.model().eventCount(), 2u); // one per contact
}

TEST(GrainsLoadMemory, OnlyFrozenSnowSetsItAndTheRangeIsChecked) {
    for (const auto& info : listSurfaces()) {
        auto s = Surface::loadById(info.id);
        for (int i = 0; i < s->layerCount(); ++i) {
            const auto* g = dynamic_cast<const GrainsLayer*>(&s->layer(i));
            if (g && info.id != "frozen_snow") {
                EXPECT_EQ(g->control().felicityRatio, 0.0) << info.id << " layer " << i;
            }
        }
    }
    auto frozen = Surface::loadById("frozen_snow");
    auto* crust = dynamic_cast<const GrainsLayer*>(&frozen->layer(0));
    ASSERT_NE(crust, nullptr);
    EXPECT_EQ(crust->control().felicityRatio, 1.0);
    const std::string preset = "id = \"m\"\nname = \"m\"\ncategory = \"aggregate\"\n"
                               "description = \"a crust\"\n"
                               "[[layer]]\ntype = \"grains\"\npurpose = \"a crust breaking\"\n"
                               "events_per_kn_rise = 10.0\nfelicity_ratio = ";
    EXPECT_NO_THROW(loadSurfaceFromString(preset + "0.9\n", "memory.toml"));
    try {
        loadSurfaceFromString(preset + "1.5\n", "memory.toml");
        ADD_FAILURE() << "felicity_ratio 1.5 accepted";
    } catch (const PresetError& e) {
        EXPECT_NE(std::string(e.what()).find("felicity_ratio"), std::string::npos) << e.what();
    }
}
