// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Public rendering API of the wading simulation (the wading study, docs/explanation/studies.md):
/// what the studies (experiment/, the listening-test mode) and the CLI call. Everything here runs
/// the same WadingScene as the live path, block by block; the same options and seed give
/// byte-identical audio.
#include "engine/control/GyroFrame.h"
#include "engine/io/AudioFile.h"
#include "engine/render/AudioFeatures.h"
#include "engine/render/SafetyLimiter.h"

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace underfoot::engine {

/// Everything that selects one wading stimulus.
struct WadingOptions {
    std::string depth = "shallow";          ///< "shallow" (ankle), "deep" (thigh) or a preset path
    std::string algorithm = "v2";           ///< "v1" (thigh only) or "v2" (thigh + shank)
    std::string filter = "butterworth_5hz"; ///< butterworth_5hz, butterworth_0_8hz, asymmetric
    double cadenceStepsPerMin = 63;         ///< virtual gait cadence; 0 = standing still
    double strideM = 0;          ///< virtual gait stride (two steps), metres; 0 = from the cadence
    std::uint64_t seed = 1;      ///< seeds the gait variability and every layer
    double sampleRateHz = 48000; ///< output rate
};

/// A wading option or parameter that is not valid; the message names the key and what it accepts.
struct WadingOptionError : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

/// Named cadences of the studies (paper, experiment 3: 27 / 63 / 118 steps per minute).
inline constexpr double kSlowCadence = 27.0, kNormalCadence = 63.0, kFastCadence = 118.0;

/// Options from a protocol's `wading = { ... }` table (and the factorial's factors): keys depth
/// (shallow/deep), algorithm (v1/v2), filter (butterworth_5hz/butterworth_0_8hz/asymmetric),
/// cadence (slow/normal/fast or steps per minute), stride_m, seed, sample_rate_hz. Unknown keys
/// and bad values throw WadingOptionError naming the key and the accepted values.
WadingOptions wadingOptionsFromParameters(const std::map<std::string, std::string>& params);

/// Throws WadingOptionError when an option is out of its domain (names the option).
void validateWadingOptions(const WadingOptions& options);

/// Renders `seconds` of stereo audio driven by the virtual gait (options.cadenceStepsPerMin,
/// options.strideM, seeded by options.seed).
/// The output passes the same safety limiter as every render (engine/render/SafetyLimiter.h);
/// `limiter`, when given, receives whether and how much it acted.
AudioBuffer renderWading(const WadingOptions& options, double seconds,
                         LimiterReport* limiter = nullptr);

/// Renders stereo audio driven by recorded gait frames (100 Hz, e.g. from readGaitCsv()); the
/// length is that of the recording. Cadence and stride of the options are not used.
AudioBuffer renderWading(const WadingOptions& options, const std::vector<GaitFrame>& gait,
                         LimiterReport* limiter = nullptr);

/// Deep against shallow water for one gait: both depths rendered with the same options (the
/// virtual gait at `cadence`, algorithm, seed), with their features. The depth cue is the
/// difference of the equivalent levels (RMS over the whole render, AudioFeatures::leqDb).
struct WadingDepthContrast {
    AudioFeatures shallow, deep;
    double contrastDb() const { return deep.leqDb - shallow.leqDb; }
};
WadingDepthContrast measureDepthContrast(WadingOptions options, double seconds);

} // namespace underfoot::engine
