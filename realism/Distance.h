// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The realism distance between synthetic steps and recorded steps.
///
/// Definition (documented in docs/explanation/realism.md): for every scalar descriptor d, take the
/// median of the synthetic steps, m_s, and the median m_r and interquartile range IQR_r of the
/// recorded steps, all on the descriptor's comparison scale (log2 for frequencies, rates and times,
/// i.e. octaves; dB as they are). Its robust z-score is
///     z_d = |m_s - m_r| / clamp(IQR_r / 1.349, s_d, 2 s_d)
/// (IQR / 1.349 is the standard deviation of a normal distribution with that IQR). The scale
/// s_d is a tolerance a listener would grant (0.5 octave for frequencies, rates and times, 3 dB
/// for levels and ratios): below it, two near-identical recordings would make any difference
/// look huge; above twice it, a heterogeneous set (two sources far apart) would make anything
/// look close, and distances to different materials would not be comparable.
/// The distance is the mean of z_d over the scalar descriptors: 0 when the synthetic medians
/// sit on the recorded ones, about 1 when they are one recorded spread away on average.
#include "realism/Descriptors.h"

#include <array>
#include <vector>

namespace underfoot::realism {

struct DescriptorComparison {
    double synthetic = 0; ///< median of the synthetic steps (descriptor's unit)
    double realMedian = 0, realQ1 = 0, realQ3 = 0; ///< recorded steps (descriptor's unit)
    double z = 0;                                  ///< robust z-score (see above)
};

struct Comparison {
    std::array<DescriptorComparison, kDescriptorCount> d{};
    double distance = 0;
    int syntheticSteps = 0, realSteps = 0;
};

/// Value on the comparison scale (log2 for logScale descriptors).
double comparisonScale(int descriptor, double value);

/// Median and quartiles (linear interpolation, as R's type 7) of a non-empty sample.
double quantile(std::vector<double> values, double q);

/// Compares two sets of steps. Throws std::invalid_argument when either is empty.
Comparison compareSteps(const std::vector<StepDescriptors>& synthetic,
                        const std::vector<StepDescriptors>& real);

} // namespace underfoot::realism
