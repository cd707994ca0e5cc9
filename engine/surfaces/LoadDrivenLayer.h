// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// What the "grains" and "bubbles" layers (GranularLayers.h, LiquidLayers.h) share: the ground
/// reaction force read sample by sample (its smoothed derivative dF/dt in kN/s; a load appearing
/// from no contact by more than kJumpN within one sample taken as already there, a cut), sleeping
/// once the foot is off the ground and the sound has rung out, and waking at the first sample in
/// contact. The sleep decision is taken on the sleep grid (engine/dsp/SleepGrid.h): the output does
/// not depend on the host's block size. No allocation after prepare(), no locks, no exceptions.
#include "engine/dsp/Envelope.h"
#include "engine/dsp/ProcessSpec.h"
#include "engine/dsp/SleepGrid.h"
#include "engine/surfaces/Layer.h"
#include "engine/surfaces/LoadInput.h"

#include <algorithm>

namespace underfoot::engine {

class LoadDrivenLayer : public SurfaceLayer {
  public:
    void process(const float* grf, float* out, int n) noexcept final {
        if (chunk_ == 0) return; // not prepared
        sleepGrid_.split(n, [&](int offset, int length, bool atGridPoint) {
            for (int done = 0; done < length; done += chunk_)
                processChunk(grf + offset + done, out + offset + done,
                             std::min(chunk_, length - done));
            if (atGridPoint) sleepDecision();
        });
    }
    bool isSleeping() const noexcept final { return sleeping_; }

  protected:
    /// A rise from no contact by more than this (N) in one sample is a cut, not a landing.
    static constexpr double kJumpN = 100.0;

    /// From prepare(), before the layer's own: the rate, the smoothing of dF/dt, the load below
    /// which the foot is off the ground, how long the layer rings on after its last contact
    /// before it may sleep, and the longest span processAwake() is given (the block size).
    void prepareLoad(const ProcessSpec& spec, double derivativeMs, double contactThresholdN,
                     double tailSeconds) noexcept {
        sampleRateHz_ = spec.sampleRateHz;
        toKnPerS_ = sampleRateHz_ * 1e-3;
        derivativeG_ = onePoleCoefficientTau(derivativeMs * 1e-3, sampleRateHz_);
        thresholdN_ = contactThresholdN;
        tailLength_ = static_cast<int>(tailSeconds * sampleRateHz_);
        chunk_ = std::max(1, spec.maxBlockSize);
    }
    /// From reset(): no load, asleep, the sleep grid at its start.
    void resetLoad() noexcept {
        previousF_ = 0.0;
        derivative_ = 0.0;
        sleeping_ = true;
        tailSamples_ = 0;
        sleepGrid_.reset();
        contactSinceGridPoint_ = false;
    }
    /// One awake sample's load f (N, sanitised): advances dF/dt. Returns true when f is a cut
    /// (no foot lands this fast: the GRF starts mid-stance), which is then taken as already
    /// there: no rise.
    bool trackLoad(double f) noexcept {
        const bool jump = previousF_ <= thresholdN_ && f - previousF_ > kJumpN;
        if (jump) previousF_ = f;
        const double raw = (f - previousF_) * toKnPerS_;
        previousF_ = f;
        derivative_ = raw + derivativeG_ * (derivative_ - raw);
        return jump;
    }

    /// The layer's samples from its first in contact after waking (n <= the block size): adds
    /// its sound into out. Returns true when any of the n samples was in contact.
    virtual bool processAwake(const float* grf, float* out, int n) noexcept = 0;
    /// At a grid point while awake: flushes the layer's tiny state; true when it is silent.
    virtual bool settleTail() noexcept = 0;
    /// The layer has rung out: it clears its state before sleeping.
    virtual void fallAsleep() noexcept = 0;

    double sampleRateHz_ = 48000.0;
    double thresholdN_ = 5.0;  ///< contact threshold (N)
    double previousF_ = 0.0;   ///< the last sample's load (N)
    double derivative_ = 0.0;  ///< smoothed dF/dt (kN/s)
    double derivativeG_ = 0.0; ///< its one-pole coefficient
    double toKnPerS_ = 48.0;   ///< N per sample -> kN/s
    int tailLength_ = 0;       ///< samples without contact and silent before sleeping

  private:
    void processChunk(const float* grf, float* out, int n) noexcept {
        if (sleeping_) {
            // The layer wakes at the first sample in contact. Until then only the load's smoothed
            // derivative is tracked (as awake), so a landing's rise is the same whenever it wakes.
            const int first = trackLoadUntilContact(grf, n, thresholdN_, toKnPerS_, derivativeG_,
                                                    previousF_, derivative_);
            if (first == n) return;
            sleeping_ = false;
            tailSamples_ = 0;
            grf += first;
            out += first;
            n -= first;
        }
        contactSinceGridPoint_ |= processAwake(grf, out, n);
    }
    void sleepDecision() noexcept {
        const bool contactSeen = contactSinceGridPoint_;
        contactSinceGridPoint_ = false;
        derivative_ = snapToZero(derivative_);
        if (sleeping_) return;
        const bool silent = settleTail();
        if (!contactSeen && silent) {
            tailSamples_ += kSleepGridSamples; // (awake for the whole span: no contact in it)
            if (tailSamples_ >= tailLength_) { // rung out: sleep with clean state
                fallAsleep();
                sleeping_ = true; // (the load's derivative is still tracked while asleep)
            }
        } else {
            tailSamples_ = 0;
        }
    }

    int chunk_ = 0; ///< the block size; 0 before prepare()
    bool sleeping_ = true;
    int tailSamples_ = 0;
    SleepGrid sleepGrid_;
    bool contactSinceGridPoint_ = false;
};

} // namespace underfoot::engine
