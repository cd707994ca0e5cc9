// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/control/GrfBank.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace underfoot::engine {

double heelShare(double s) noexcept {
    if (s <= 0.3) return 1.0;
    if (s >= 0.6) return 0.0;
    const double c = std::cos(0.5 * kPi * (s - 0.3) / 0.3);
    return c * c;
}

GrfBank makeGrfBank(const WalkerParameters& walker, int count, std::uint64_t seed,
                    double sampleRateHz) {
    if (count < 1 || count > 100)
        throw std::invalid_argument(fmt::format("GRF bank: count {} outside [1, 100]", count));
    walker.validate();
    VirtualWalker w(walker);
    w.prepare({sampleRateHz, 1024});
    w.reset(seed);
    GrfBank bank;
    std::vector<float> left(1024), right(1024), stance;
    bool inStance = false;
    // Skip the first left stance (it starts at sample 0, fine, but keep the same treatment for
    // all: collect complete stances that start after sample 0).
    bool skippedFirst = false;
    while (static_cast<int>(bank.heel.size()) < count) {
        w.process(left.data(), right.data(), 1024);
        for (float f : left) {
            if (f > 0) {
                inStance = true;
                stance.push_back(f);
            } else if (inStance) {
                inStance = false;
                if (!skippedFirst) {
                    skippedFirst = true;
                } else if (static_cast<int>(bank.heel.size()) < count) {
                    const std::size_t n = stance.size() + 1; // include the zero before contact
                    GrfSignal heel, toe;
                    heel.sampleRateHz = toe.sampleRateHz = sampleRateHz;
                    heel.names = {"heel"};
                    toe.names = {"toe"};
                    std::vector<float> h(n, 0.0f), t(n, 0.0f);
                    for (std::size_t i = 0; i < stance.size(); ++i) {
                        const double s = static_cast<double>(i + 1) / static_cast<double>(n);
                        const double share = heelShare(s);
                        h[i + 1] = static_cast<float>(stance[i] * share);
                        t[i + 1] = static_cast<float>(stance[i] - h[i + 1]);
                    }
                    const float toePeak = *std::max_element(t.begin(), t.end());
                    const auto onset = static_cast<std::size_t>(
                        std::find_if(t.begin(), t.end(),
                                     [&](float v) { return v > 0.01f * toePeak; }) -
                        t.begin());
                    const std::size_t start = onset > 0 ? onset - 1 : 0;
                    heel.channels = {std::move(h)};
                    toe.channels = {
                        std::vector<float>(t.begin() + static_cast<long>(start), t.end())};
                    toe.channels[0].push_back(0.0f);
                    heel.channels[0].push_back(0.0f);
                    bank.heel.push_back(std::move(heel));
                    bank.toe.push_back(std::move(toe));
                }
                stance.clear();
            }
        }
    }
    return bank;
}

} // namespace underfoot::engine
