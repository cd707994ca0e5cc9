// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The "friction" layer's settings and its drive (engine/surfaces/SolidLayers.cpp): how the
/// vertical GRF makes old boards creak. While the load changes faster than a threshold, the
/// boards shear: an anchor moves with a speed proportional to the load's smoothed rate of change
/// and drags a rubbing mass through a stiff spring across the boards' creak resonances; a share
/// of the load presses the rubbing surfaces together. Stick-slip of that contact
/// (ElastoPlasticFriction) makes the creak.
///
/// The layer and the friction benchmark (tests/bench/bench_friction.cpp) both read a preset
/// through readFrictionLayer() and drive the model through FrictionDrive, so the benchmark times
/// exactly the inputs a shipped preset gives the model, with no copy of its values or its drive.
#include "engine/dsp/Envelope.h"
#include "engine/models/Friction.h"
#include "engine/surfaces/Layer.h"
#include "engine/surfaces/LoadInput.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace underfoot::engine {

struct FrictionDriveParams {
    double normalFraction = 0.2; ///< share of the GRF pressing the rubbing surfaces
    double slipPerRate = 0.002;  ///< shear speed in m/s per kN/s of load change
    double threshold = 500.0;    ///< N/s: load change below which the boards do not shear
    /// m/s: the model's output below which the boards count as rung out (the layer: -120 dBFS
    /// after its gain)
    double sleepVelocity = 1e-7;
    /// The boards' roughness (the model's noise) keeps rubbing for settling.afterS after the last
    /// shear, then fades out: a load held still lets the boards ring out and sleep
    LoadSettling::Params settling;
};

/// Everything a "friction" layer reads from its preset table.
struct FrictionLayerSettings {
    FrictionParams model; ///< the contact (driveStiffness / driveDamping: the drag's spring)
    std::vector<Mode> modes;
    std::vector<double> gains; ///< mode shapes at the rubbing point
    FrictionDriveParams drive;
    double gain = 1.0; ///< output gain (1: 1 m/s = full scale)
};

/// Reads a "friction" layer's table (every key, with its unit and range: see SolidLayers.cpp);
/// throws PresetError naming the file, the place and what was expected.
FrictionLayerSettings readFrictionLayer(PresetReader& reader, const AccuracyOptions& options);

/// Turns the GRF into the friction model's inputs, sample by sample, and decides when the
/// boards sleep: while nothing shears and the boards have rung out (standing still or in the
/// air) the model is not run and its state is held. No allocation; noexcept.
///
/// Per GRF sample: `next()` says whether to run the model and with what (it relaxes the model
/// itself when the foot is off the floor); after running it, `settle()` takes its output.
class FrictionDrive {
  public:
    struct Input {
        double normal;         ///< N pressing the rubbing surfaces
        double anchor;         ///< m: where the drag's spring is anchored
        double anchorVelocity; ///< m/s: the shear speed
        /// scale of the model's roughness noise: 1 while the boards shear and for
        /// settling.afterS after, then fading to 0 (a load held still lets them fall asleep)
        double roughness;
        bool unloaded; ///< no load: next() relaxed the model (a replay must do the same)
    };

    void configure(const FrictionDriveParams& params) noexcept { params_ = params; }
    void prepare(double sampleRateHz) noexcept {
        fs_ = sampleRateHz;
        smooth_ = onePoleCoefficientTau(0.005, fs_);
        settling_.prepare(params_.settling, fs_);
        sleepAfter_ = static_cast<long>(0.05 * fs_);
    }
    void reset() noexcept {
        last_ = rate_ = anchor_ = 0.0;
        quiet_ = 1L << 30;
        settling_.reset();
    }

    /// One GRF sample (N). false: the boards sleep, do not run the model for this sample.
    [[gnu::always_inline]] bool next(float grf, ElastoPlasticFriction& model, Input& in) noexcept {
        const double load = std::max(0.0f, grf);
        const double d = (load - last_) * fs_;
        last_ = load;
        rate_ = d + smooth_ * (rate_ - d);
        const double shear =
            std::max(0.0, std::fabs(rate_) - params_.threshold) * 1e-3 * params_.slipPerRate;
        if (shear <= 0.0 && quiet_ > sleepAfter_) {
            anchor_ = model.exciterPosition();
            return false;
        }
        anchor_ += shear / fs_;
        in.unloaded = load <= 0.0;
        if (in.unloaded) { // unloaded: the drag and the bristles relax
            anchor_ = model.exciterPosition();
            model.relax();
            settling_.reset();
        }
        in.normal = params_.normalFraction * load;
        in.anchor = anchor_;
        in.anchorVelocity = shear;
        in.roughness = settling_.next(shear > 0.0);
        return true;
    }
    /// The model's output for the sample next() let through (with next()'s input).
    [[gnu::always_inline]] void settle(double y, const Input& in,
                                       const ElastoPlasticFriction& model) noexcept {
        const bool still = in.unloaded || std::fabs(model.relativeVelocity()) < 1e-6;
        quiet_ = (std::fabs(y) < params_.sleepVelocity && still) ? quiet_ + 1 : 0;
    }
    /// Asleep now, and the load is not changing fast enough to wake the boards.
    bool isSleeping() const noexcept {
        return quiet_ > sleepAfter_ && std::fabs(rate_) <= params_.threshold;
    }

  private:
    FrictionDriveParams params_;
    LoadSettling settling_;
    double fs_ = 48000.0, smooth_ = 0.0, last_ = 0.0, rate_ = 0.0, anchor_ = 0.0;
    long quiet_ = 1L << 30, sleepAfter_ = 2400;
};

} // namespace underfoot::engine
