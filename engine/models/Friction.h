// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Elasto-plastic friction between an inertial exciter (the sole, or a board edge) and a modal
/// resonator (the boards), after Dupont, Hayward, Armstrong & Altpeter, "Single state
/// elastoplastic friction models", IEEE Trans. Automatic Control 47(5), 2002, as used for
/// creaking sounds by Avanzini, Serafin & Rocchesso (2005) and the Sound Design Toolkit.
///
///   f = sigma0 z + sigma1 z' + sigma2 v + sigma3 w          (w: uniform noise, roughness)
///   z' = v (1 - alpha(z, v) z / z_ss(v))
///   z_ss(v) = sgn(v) [f_c + (f_s - f_c) exp(-(v/v_s)^2)] / sigma0   (Stribeck)
///   alpha = 0 for |z| <= z_ba (pure stick), 1 for |z| >= |z_ss|, a raised sine in between,
///   and 0 when z and v have opposite signs.
/// f_c = mu_d N and f_s = mu_s N follow the normal force N (here: the GRF).
///
/// Discretisation: the exciter and the resonator respond to the friction force at n+1 through
/// their instantaneous mobilities (exact first-order-hold integration, as in Impact.h); the
/// bristle state is integrated with backward Euler (alpha taken at z_n), which is unconditionally
/// stable — the forward Euler of the Sound Design Toolkit blows up for sigma0 above ~5e7. The
/// relative velocity at n+1 follows in closed form once the plastic factor alpha / z_ss is taken
/// at a trial velocity; `maxIterations` fixed-point passes refine that trial (bounded work).
#include "engine/dsp/Random.h"
#include "engine/models/ModalResonator.h"

namespace underfoot::engine {

struct FrictionParams {
    double sigma0 = 1e5;             ///< bristle stiffness, N/m
    double sigma1 = 300.0;           ///< bristle damping, N s/m
    double sigma2 = 0.5;             ///< viscous friction, N s/m
    double sigma3 = 0.0;             ///< noise (roughness) amplitude, N
    double staticCoefficient = 0.6;  ///< mu_s: static friction per newton of normal force
    double dynamicCoefficient = 0.3; ///< mu_d: Coulomb friction per newton of normal force
    double stribeckVelocity = 0.05;  ///< v_s, m/s
    double breakAway = 0.7;          ///< z_ba as a fraction of the static deflection f_c / sigma0
    double exciterMassKg = 0.05;     ///< mass of the rubbing body
    double driveStiffness = 0.0;     ///< N/m: spring dragging the rubbing body from an anchor
    double driveDamping = 0.0;       ///< N s/m: damper in parallel with that spring
    int maxIterations = 3;           ///< fixed-point passes per sample (bounded work)
};

template <typename Real>
class ElastoPlasticFrictionT {
  public:
    void configure(const FrictionParams& params, std::vector<Mode> modes,
                   std::vector<std::vector<double>> gains);
    void prepare(double sampleRateHz);
    void reset(std::uint64_t seed) noexcept;

    /// One sample: `normalForceN` presses the bodies together, `driveForceN` pushes the exciter
    /// tangentially and the drive spring/damper pulls it towards an anchor at `anchorPosition`
    /// moving at `anchorVelocity` (integrated implicitly: an explicit stiff drag would delay its
    /// force by a sample and pump energy in). Returns the resonator's velocity at pickup 0 (m/s).
    double processSample(double normalForceN, double driveForceN, double anchorPosition = 0.0,
                         double anchorVelocity = 0.0) noexcept;

    /// Unloaded surfaces: the bristles relax and the rubbing mass stops (keeps the ringing).
    void relax() noexcept { z_ = exciterV_ = force_ = lastExternal_ = v_ = 0.0; }
    double frictionForce() const noexcept { return force_; }
    double bristle() const noexcept { return z_; }
    double relativeVelocity() const noexcept { return v_; }
    double exciterVelocity() const noexcept { return exciterV_; }
    double exciterPosition() const noexcept { return exciterX_; }
    const ModalResonatorT<Real>& resonator() const noexcept { return resonator_; }
    ModalResonatorT<Real>& resonator() noexcept { return resonator_; }

  private:
    double alphaOf(double z, double v, double zss, double zba) const noexcept;

    FrictionParams params_;
    ModalResonatorT<Real> resonator_;
    Random rng_;
    double T_ = 1.0 / 48000.0;
    double kd_ = 0.0;
    double m11_ = 1, m12_ = 0, m21_ = 0, m22_ = 1, det_ = 1; // implicit drive (see .cpp)
    double px_ = 0, pv_ = 0; // exciter compliance / mobility to the friction force
    double z_ = 0, v_ = 0, force_ = 0, exciterX_ = 0, exciterV_ = 0, lastExternal_ = 0;
};

using ElastoPlasticFriction = ElastoPlasticFrictionT<double>;

} // namespace underfoot::engine
