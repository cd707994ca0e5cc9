// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/Distance.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace underfoot::realism {

double comparisonScale(int descriptor, double value) {
    return descriptorInfo(descriptor).logScale ? std::log2(std::max(value, 1e-9)) : value;
}

double quantile(std::vector<double> v, double q) {
    if (v.empty()) throw std::invalid_argument("quantile of an empty sample");
    std::sort(v.begin(), v.end());
    const double h = (double(v.size()) - 1.0) * q;
    const auto lo = static_cast<std::size_t>(std::floor(h));
    const auto hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (h - double(lo)) * (v[hi] - v[lo]);
}

Comparison compareSteps(const std::vector<StepDescriptors>& synthetic,
                        const std::vector<StepDescriptors>& real) {
    if (synthetic.empty()) throw std::invalid_argument("no synthetic steps to compare");
    if (real.empty()) throw std::invalid_argument("no recorded steps to compare with");
    Comparison c;
    c.syntheticSteps = static_cast<int>(synthetic.size());
    c.realSteps = static_cast<int>(real.size());
    double sum = 0;
    for (int d = 0; d < kDescriptorCount; ++d) {
        const auto di = static_cast<std::size_t>(d);
        std::vector<double> s, r;
        for (const auto& x : synthetic) s.push_back(comparisonScale(d, x.value[di]));
        for (const auto& x : real) r.push_back(comparisonScale(d, x.value[di]));
        const double ms = quantile(s, 0.5), mr = quantile(r, 0.5);
        const double q1 = quantile(r, 0.25), q3 = quantile(r, 0.75);
        auto& out = c.d[di];
        const bool lg = descriptorInfo(d).logScale;
        auto back = [lg](double v) { return lg ? std::exp2(v) : v; };
        out.synthetic = back(ms);
        out.realMedian = back(mr);
        out.realQ1 = back(q1);
        out.realQ3 = back(q3);
        const double floor = descriptorInfo(d).floor;
        out.z = std::fabs(ms - mr) / std::clamp((q3 - q1) / 1.349, floor, 2.0 * floor);
        sum += out.z;
    }
    c.distance = sum / double(kDescriptorCount);
    return c;
}

} // namespace underfoot::realism
