// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Per-participant calibration of the step detector (Turchet et al. 2010: "thresholds are
/// calibrated per participant weight"). From a short recording of the participant walking (and
/// standing), each heel/toe sensor's rest level, step peak level, derivative noise at rest and the
/// derivative peaks of its foot strikes are measured, and thresholds are proposed
/// (docs/reference/sensors.md, "Step thresholds file"):
///   rest  = 5th percentile of the pressure, peak = 99th percentile, range = peak - rest
///   strikes = rises from below rest + 0.2 range to above rest + 0.5 range; each strike's
///             derivative peak is taken over the rise
///   onset_derivative = max(0.35 x the 10th percentile of strike peaks, 2 x the derivative noise
///             at rest (99.9th percentile of |d| inside runs below rest + 0.1 range, 30 frames
///             away from their ends, so that no rise or fall counts as noise))
///   contact = rest + 0.08 range, release = rest + 0.25 range,
///   reference_derivative = median strike peak (strength 1).
/// A warning is given when the noise term exceeds half the 10th-percentile strike peak (soft
/// strikes may then be missed).
/// Thresholds are saved and loaded as TOML, one file per participant.
#include "engine/control/StepDetector.h"

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

namespace underfoot::engine {

/// A recording cannot be calibrated (no steps on a sensor, too short, ...); the message names the
/// sensor and what was expected.
struct CalibrationError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// What was measured on one sensor.
struct SensorCalibrationStats {
    double restLevel = 0;
    double peakLevel = 0;
    double noiseDerivativePerS = 0;  ///< 99.9th percentile of |derivative| at rest
    std::size_t strikes = 0;         ///< foot strikes found
    double strikePeakMedianPerS = 0; ///< median derivative peak of the strikes
    double strikePeakP10PerS = 0;    ///< 10th percentile
};

/// The proposal and what it was based on.
struct StepCalibrationResult {
    StepThresholds thresholds;
    std::array<SensorCalibrationStats, kShoeSensorCount> stats{};
    std::vector<std::string> warnings; ///< e.g. "left_toe: strikes barely above the noise"
};

/// Settings of the calibration.
struct StepCalibrationOptions {
    std::string participant;
    double frameRateHz = 1000;
    double derivativeSpanMs = 4;
    double refractoryMs = 120;
    double releaseHoldMs = 20;
    std::size_t minStrikes = 4; ///< per sensor
    double minRangeUnits = 40;  ///< peak - rest below this: the sensor saw no steps
};

/// Proposes thresholds from a recording (raw frames at frameRateHz). Throws CalibrationError.
StepCalibrationResult calibrateSteps(const std::vector<ShoeFrame>& recording,
                                     const StepCalibrationOptions& options = {});

/// Writes thresholds as TOML (format "underfoot-step-thresholds", version 1). Throws
/// std::runtime_error naming the file when it cannot be written.
void saveStepThresholds(const std::string& path, const StepThresholds& thresholds,
                        const StepCalibrationResult* measured = nullptr);
/// Reads thresholds written by saveStepThresholds. Throws std::runtime_error naming the file, the
/// line:column and what was expected.
StepThresholds loadStepThresholds(const std::string& path);

} // namespace underfoot::engine
