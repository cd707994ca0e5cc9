// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Latency of the wading simulation from a gyroscope frame to sound, measured on the real scene
/// (the CLI's `underfoot wade --latency` and tests/wading/engine/test_wading_latency.cpp).
///
/// Set-up: the walker stands still (silence) and, at t = 0.2 s, every limb's angular velocity
/// steps to `stepDps` in one 100 Hz frame. The frame is delivered as the live path does it: it
/// arrives one sample after an audio block has started (the worst case), is handed to the scene
/// with pushFrame() before the next block, and takes effect at that block's first sample.
///  - plumbing: from the frame's arrival to the first output sample that is not zero, and to the
///    first above -60 dBFS ("audible" against the silence before);
///  - dynamics: from the arrival to the first 5 ms window whose RMS is within 6 dB of the settled
///    level (mean RMS 1.0-1.5 s after the step); this includes the paper's deliberate smoothing;
///  - filter group delay: the low-pass's group delay at 0 Hz (analytic for the biquad), and at
///    1 Hz (the gait's fundamental region), of the thigh filter.
#include "engine/wading/Wading.h"

namespace underfoot::engine {

struct WadingLatencyReport {
    double framePeriodMs = 10;      ///< sensor frame period
    double blockMs = 0;             ///< audio block duration
    double firstChangeMs = 0;       ///< arrival -> first non-zero sample
    double firstAudibleMs = 0;      ///< arrival -> first sample above -60 dBFS
    double withinSixDbMs = 0;       ///< arrival -> 5 ms RMS within 6 dB of the settled level
    double groupDelayDcMs = 0;      ///< low-pass group delay at 0 Hz (left thigh)
    double groupDelay1HzMs = 0;     ///< at 1 Hz
    double rightGroupDelayDcMs = 0; ///< right thigh (differs for the asymmetric filter)
};

/// Measures the latencies above for `options` (depth, algorithm, filter, seed, rate) with audio
/// blocks of `blockSize` samples and a step of `stepDps` deg/s.
WadingLatencyReport measureWadingLatency(const WadingOptions& options, int blockSize = 256,
                                         double stepDps = 200.0);

} // namespace underfoot::engine
