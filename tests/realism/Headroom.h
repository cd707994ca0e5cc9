// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Headroom measurement shared by test_headroom.cpp and soak/test_headroom_soak.cpp.
#include "engine/render/Renderer.h"
#include "engine/surfaces/Surface.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

namespace underfoot::test {
using namespace underfoot::engine;
inline constexpr double kLimitDb = -1.3; // 1 dB below the limiter's -0.3 dBFS ceiling

// Peak of the scene before the limiter, dBFS: the output's own peak when the limiter did not
// act (it is bit-transparent then), else ceiling + its deepest reduction (instant attack).
inline double scenePeakDb(const RenderResult& r) {
    if (r.limiter.acted()) return -0.3 + r.limiter.maxReductionDb;
    float peak = 0;
    for (float v : r.audio.samples) peak = std::max(peak, std::fabs(v));
    return 20 * std::log10(std::max(peak, 1e-9f));
}

struct WorstPeak {
    double db = -300;  ///< dBFS, before the limiter
    std::string where; ///< walker and seed of that render
};

// Worst peak per surface over the walkers and seeds given.
inline std::map<std::string, WorstPeak> worstPeaks(const std::vector<std::string>& walkers,
                                                   int seeds, double seconds) {
    std::map<std::string, WorstPeak> worst;
    // UNDERFOOT_HEADROOM_SURFACES=deep_snow,gravel limits a run to those surfaces (re-checking
    // one preset without the whole soak).
    const char* only = std::getenv("UNDERFOOT_HEADROOM_SURFACES");
    const std::string onlyList = only ? "," + std::string(only) + "," : "";
    for (const auto& info : listSurfaces())
        for (const auto& walker : walkers)
            for (int seed = 1; seed <= seeds; ++seed) {
                if (!onlyList.empty() && onlyList.find("," + info.id + ",") == std::string::npos)
                    break;
                const auto grf =
                    walkerGrf(WalkerParameters::parse(walker), seconds, 48000, std::uint64_t(seed));
                RenderOptions o;
                o.seed = std::uint64_t(seed);
                o.tailSeconds = 0.5;
                const double p = scenePeakDb(renderSurface(info.id, grf, o));
                auto& w = worst[info.id];
                if (p > w.db) w = {p, walker + " seed " + std::to_string(seed)};
            }
    return worst;
}

// Every surface has the same limit: 1 dB below the limiter's ceiling. The aggregates' grains are
// held there for heavy walkers by their energy bound (energy_saturation, amplitude_cap:
// engine/surfaces/GranularLayers.h, docs/explanation/realism.md "Levels"), not by exceptions.
inline double peakLimitDb(const std::string&) {
    return kLimitDb;
}

inline void printPeaks(const std::map<std::string, WorstPeak>& worst) {
    for (const auto& [id, w] : worst)
        std::printf("  %-22s worst peak %6.2f dBFS (%s), limit %.1f dBFS\n", id.c_str(), w.db,
                    w.where.c_str(), peakLimitDb(id));
}

inline void expectWithinLimits(const std::map<std::string, WorstPeak>& worst) {
    for (const auto& [id, w] : worst) EXPECT_LE(w.db, peakLimitDb(id)) << id << ": " << w.where;
}
} // namespace underfoot::test
