// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Gait inputs of the wading simulation, all producing GaitFrame values at 100 Hz:
///  - the virtual gait: plausible sagittal angular velocities of both thighs and shanks for a
///    cadence and a stride, left and right in antiphase, seeded step-to-step variability;
///  - recorded gait CSV files (time, left/right thigh/shank) read and written;
///  - GaitFrameAssembler: live GyroSamples (one OSC packet per limb) into 100 Hz frames.
///
/// Virtual gait model (documented choices; sources in docs/explanation/wading.md):
///  - steps alternate left/right, each lasting 60 / cadence s (x a seeded jitter); a limb's
///    stride runs from its heel strike to its next one; its swing is the last Tsw of the stride,
///    Tsw = min(0.4 T, 0.25 s + 0.15 T) for stride time T (swing ~40 % of the cycle at normal
///    walking, Perry & Burnfield 2010; proportionally shorter when walking very slowly);
///  - stride: given, or from the cadence (0.6 m + 0.0075 m per step/min);
///  - thigh: forward rotation by the hip excursion Th = 2 atan(stride / (4 legLength)) during the
///    swing, backward by the same angle during the stance (no drift); shank: forward rotation of
///    1.6 Th in the swing, peaking later (mid-to-late swing, when the knee extends; paper Fig. 3),
///    backward during stance;
///  - every excursion follows a normalised beta-shaped bump u^p (1-u)^q over its phase, so the
///    integral of each angular velocity over a phase is exactly that phase's excursion; thigh
///    swing peaks at u = 0.39 (p = 1.3, q = 2), shank swing at u = 0.56 (p = 2, q = 1.6), stances
///    with p = q = 1.5;
///  - variability: relative Gaussian jitter (sd `variability`) of each step duration and of each
///    swing's amplitude, clamped at 2 sd (engine/dsp/Random.h, seeded);
///  - cadence 0: standing still (all angular velocities exactly 0).
#include "engine/control/GyroFrame.h"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace underfoot::engine {

/// Frame rate of gait data in the whole wading chain (the paper's sensors stream at 100 Hz).
inline constexpr double kGaitFrameRateHz = 100.0;

struct VirtualGaitParameters {
    double cadenceStepsPerMin = 63; ///< 0 (standing) or [10, 160] steps per minute
    double strideM = 0;             ///< stride (two steps), [0.2, 2.5] m; 0 = from the cadence
    double legLengthM = 0.9;        ///< hip to ground, [0.5, 1.2] m
    double variability = 0.03;      ///< relative sd of step durations and amplitudes, [0, 0.2]
    /// Throws std::invalid_argument naming the parameter and its range.
    void validate() const;
    /// Stride time (two steps) in seconds; 0 when standing.
    double strideSeconds() const noexcept {
        return cadenceStepsPerMin > 0 ? 120.0 / cadenceStepsPerMin : 0.0;
    }
    /// Swing duration for a stride time T: min(0.4 T, 0.25 + 0.15 T) seconds.
    static double swingSeconds(double strideSeconds) noexcept;
    /// The stride used: strideM, or when 0, 0.6 m + 0.0075 m x cadence (0.80 / 1.07 / 1.49 m at
    /// 27 / 63 / 118 steps/min: step length grows with cadence, Grieve & Gear 1966).
    double effectiveStrideM() const noexcept {
        return strideM > 0 ? strideM : 0.6 + 0.0075 * cadenceStepsPerMin;
    }
    /// Hip (thigh) excursion over a swing, degrees.
    double thighExcursionDeg() const noexcept;
};

/// `seconds` of virtual gait at 100 Hz, frame k at time k / 100 s (steady walking from t = 0).
std::vector<GaitFrame> virtualGait(const VirtualGaitParameters& parameters, double seconds,
                                   std::uint64_t seed);

/// A gait file problem; what() reads "file:line: what was expected".
struct GaitFileError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// Reads a gait CSV: '#' comment lines, then a header naming the columns time_s,
/// left_thigh_dps, right_thigh_dps, left_shank_dps, right_shank_dps (any order; "time",
/// "left_thigh", ... accepted; the shank columns may be absent: thigh-only recordings as in the
/// paper's first experiments, shanks read as 0), then one row of numbers per reading. Times must
/// increase strictly; rows at any regular or irregular rate are linearly interpolated onto 100 Hz
/// frames starting at the first time (which becomes t = 0). NaN/Inf, missing or extra fields,
/// unknown columns and non-numbers throw GaitFileError naming file:line and what was expected.
std::vector<GaitFrame> readGaitCsv(const std::string& path, bool* hasShanks = nullptr);

/// Parses gait CSV text (`name` is used in messages).
std::vector<GaitFrame> parseGaitCsv(const std::string& text, const std::string& name,
                                    bool* hasShanks = nullptr);

/// Writes frames as a gait CSV that readGaitCsv() reads back exactly (to 1e-6 deg/s).
void writeGaitCsv(const std::string& path, const std::vector<GaitFrame>& frames);

/// Live input: folds a stream of per-limb GyroSamples (any order, any limb) into GaitFrames.
/// Each limb holds its latest finite reading; non-finite readings are rejected (counted) and the
/// limb keeps its previous value. A frame is due each time the session clock passes a multiple of
/// the frame period; `push()` returns true and fills `frame` then (the frame carries the values
/// held at that instant). No allocation: usable on the audio or network thread.
class GaitFrameAssembler {
  public:
    void reset() noexcept;
    /// Adds a reading; true when a frame became due (written to `frame`).
    bool push(const GyroSample& sample, GaitFrame& frame) noexcept;
    /// Readings refused because they were NaN/Inf or absurd (|w| > 5000 deg/s).
    std::uint64_t rejectedSamples() const noexcept { return rejected_; }

  private:
    GaitFrame held_{};
    double nextFrameTimeS_ = -1.0;
    std::uint64_t rejected_ = 0;
};

} // namespace underfoot::engine
