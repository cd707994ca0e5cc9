// SPDX-License-Identifier: GPL-3.0-or-later
// Two hours of walking on three surfaces: no level drift, no non-finite sample, and the cost of
// the last ten minutes printed beside the first ten's (a figure, not an assertion: timings on a
// shared machine are noisy).
#include "engine/render/AudioFeatures.h"
#include "engine/render/Renderer.h"

#include <gtest/gtest.h>

#include <cstdio>

using namespace underfoot::engine;

TEST(Soak, TwoHoursOfWalkingKeepLevelAndCost) {
    const double fs = 48000.0, chunkSeconds = 600.0;
    const int chunks = 12;
    for (const std::string surface : {"wood", "gravel", "creaking_wood"}) {
        FootstepScene scene;
        scene.build(surface);
        scene.prepare({fs, 256});
        scene.reset(1);
        VirtualWalker walker;
        walker.prepare({fs, 256});
        walker.reset(1);
        std::vector<float> gl(256), gr(256), l(256), r(256);
        std::vector<double> rms, cpu;
        for (int c = 0; c < chunks; ++c) {
            double energy = 0;
            const double t0 = threadCpuSeconds();
            for (std::size_t i = 0; i < static_cast<std::size_t>(chunkSeconds * fs); i += 256) {
                walker.process(gl.data(), gr.data(), 256);
                const float* in[2] = {gl.data(), gr.data()};
                scene.process(in, l.data(), r.data(), 256);
                for (int k = 0; k < 256; ++k) {
                    ASSERT_TRUE(std::isfinite(l[static_cast<std::size_t>(k)]));
                    energy +=
                        double(l[static_cast<std::size_t>(k)]) * l[static_cast<std::size_t>(k)];
                }
            }
            cpu.push_back(threadCpuSeconds() - t0);
            rms.push_back(10 * std::log10(energy / (chunkSeconds * fs)));
        }
        std::printf("%s: RMS first/last 10 min %.2f / %.2f dBFS, CPU %.2f / %.2f s\n",
                    surface.c_str(), rms.front(), rms.back(), cpu.front(), cpu.back());
        for (double x : rms) EXPECT_NEAR(x, rms.front(), 0.5) << surface;
    }
}
