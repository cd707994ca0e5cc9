// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/models/Friction.h"

#include "engine/models/ModalKernels.h"

#include "engine/dsp/Simd.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace underfoot::engine {

// 2^(j / 256), correctly rounded: Python's decimal module at 60 digits,
//   [float(Decimal(2) ** (Decimal(j) / 256)) for j in range(256)]
// (float() of a Decimal rounds correctly).
// clang-format off
const double kFrictionExp2Table[256] = {
    1.0, 1.0027112750502025, 1.0054299011128027, 1.0081558981184175,
    1.0108892860517005, 1.0136300849514894, 1.016378314910953, 1.019133996077738,
    1.0218971486541166, 1.0246677928971357, 1.0274459491187637, 1.030231637686041,
    1.0330248790212284, 1.0358256936019572, 1.0386341019613787, 1.041450124688316,
    1.0442737824274138, 1.0471050958792898, 1.0499440858006872, 1.0527907730046264,
    1.0556451783605572, 1.0585073227945128, 1.061377227289262, 1.0642549128844645,
    1.0671404006768237, 1.0700337118202419, 1.0729348675259756, 1.075843889062791,
    1.0787607977571199, 1.0816856149932152, 1.0846183622133092, 1.0875590609177697,
    1.0905077326652577, 1.0934643990728858, 1.0964290818163769, 1.099401802630222,
    1.102382583307841, 1.1053714457017412, 1.1083684117236787, 1.1113735033448175,
    1.1143867425958924, 1.1174081515673693, 1.1204377524096067, 1.12347556733302,
    1.1265216186082418, 1.129575928566288, 1.1326385195987192, 1.1357094141578055,
    1.1387886347566916, 1.1418762039695616, 1.1449721444318042, 1.148076478840179,
    1.1511892299529827, 1.154310420590216, 1.1574400736337511, 1.1605782120274988,
    1.1637248587775775, 1.1668800369524817, 1.1700437696832502, 1.1732160801636373,
    1.1763969916502812, 1.1795865274628758, 1.182784710984341, 1.1859915656609938,
    1.189207115002721, 1.1924313825831512, 1.1956643920398273, 1.1989061670743806,
    1.202156731452703, 1.2054161090051239, 1.2086843236265816, 1.2119613992768012,
    1.215247359980469, 1.2185422298274085, 1.2218460329727576, 1.2251587936371455,
    1.22848053610687, 1.2318112847340759, 1.2351510639369334, 1.2384998981998165,
    1.241857812073484, 1.245224830175258, 1.2486009771892048, 1.2519862778663162,
    1.255380757024691, 1.2587844395497165, 1.2621973503942507, 1.2656195145788063,
    1.2690509571917332, 1.2724917033894028, 1.275941778396392, 1.2794012075056693,
    1.2828700160787783, 1.2863482295460256, 1.2898358734066657, 1.2933329732290895,
    1.2968395546510096, 1.3003556433796506, 1.3038812651919358, 1.3074164459346773,
    1.3109612115247644, 1.3145155879493546, 1.318079601266064, 1.3216532776031575,
    1.3252366431597413, 1.3288297242059544, 1.3324325470831615, 1.3360451382041458,
    1.339667524053303, 1.3432997311868353, 1.3469417862329458, 1.3505937158920345,
    1.3542555469368927, 1.3579273062129011, 1.3616090206382248, 1.365300717204012,
    1.3690024229745905, 1.3727141650876684, 1.3764359707545302, 1.380167867260238,
    1.383909881963832, 1.387662042298529, 1.3914243757719262, 1.3951969099662003,
    1.3989796725383112, 1.4027726912202048, 1.4065759938190154, 1.4103896082172707,
    1.4142135623730951, 1.4180478843204152, 1.4218926021691656, 1.4257477441054942,
    1.42961333839197, 1.433489413367789, 1.4373759974489824, 1.4412731191286257,
    1.4451808069770467, 1.449099089642035, 1.4530279958490526, 1.4569675544014438,
    1.460917794180647, 1.4648787441464057, 1.4688504333369818, 1.4728328908693675,
    1.4768261459394993, 1.4808302278224719, 1.4848451658727524, 1.488870989524397,
    1.4929077282912648, 1.4969554117672355, 1.5010140696264256, 1.5050837316234065,
    1.5091644275934228, 1.5132561874526098, 1.5173590411982147, 1.5214730189088146,
    1.5255981507445384, 1.529734466947287, 1.533881997840956, 1.5380407738316568,
    1.5422108254079407, 1.5463921831410214, 1.550584877685, 1.5547889397770887,
    1.559004400237837, 1.5632312899713576, 1.567469639965553, 1.5717194812923414,
    1.5759808451078865, 1.5802537626528246, 1.5845382652524937, 1.588834384317164,
    1.593142151342267, 1.597461597908627, 1.6017927556826934, 1.606135656416771,
    1.6104903319492543, 1.6148568142048607, 1.6192351351948637, 1.6236253270173289,
    1.6280274218573478, 1.632441451987275, 1.6368674497669644, 1.6413054476440063,
    1.645755478153965, 1.6502175739206177, 1.6546917676561943, 1.6591780921616162,
    1.6636765803267364, 1.6681872651305825, 1.6727101796415966, 1.6772453570178785,
    1.681792830507429, 1.6863526334483934, 1.6909247992693053, 1.6955093614893326,
    1.7001063537185235, 1.7047158096580513, 1.709337763100463, 1.713972247929926,
    1.718619298122478, 1.723278947746274, 1.7279512309618377, 1.732636182022311,
    1.7373338352737062, 1.7420442251551564, 1.746767386199169, 1.7515033530318782,
    1.7562521603732995, 1.761013843037584, 1.7657884359332727, 1.7705759740635547,
    1.7753764925265212, 1.7801900265154245, 1.785016611318935, 1.789856282321401,
    1.7947090750031072, 1.7995750249405351, 1.804454167806624, 1.809346539371032,
    1.8142521755003989, 1.8191711121586085, 1.8241033854070534, 1.8290490314048973,
    1.8340080864093424, 1.8389805867758937, 1.843966568958626, 1.8489660695104508,
    1.8539791250833855, 1.8590057724288205, 1.864046048397789, 1.8690999899412386,
    1.8741676341103, 1.8792490180565602, 1.8843441790323345, 1.8894531543909392,
    1.8945759815869656, 1.8997126981765553, 1.9048633418176741, 1.9100279502703899,
    1.9152065613971474, 1.9203992131630474, 1.925605943636125, 1.930826790987627,
    1.9360617934922943, 1.9413109895286405, 1.9465744175792332, 1.9518521162309783,
    1.9571441241754002, 1.9624504802089273, 1.9677712232331759, 1.9731063922552343,
    1.978456026387951, 1.9838201648502194, 1.9891988469672663, 1.9945921121709402,
};
// clang-format on

template <typename Real>
void ElastoPlasticFrictionT<Real>::configure(const FrictionParams& p, std::vector<Mode> modes,
                                             std::vector<std::vector<double>> gains) {
    auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
    auto nonNegative = [](double v) { return std::isfinite(v) && v >= 0.0; };
    if (!positive(p.sigma0) || !nonNegative(p.sigma1) || !nonNegative(p.sigma2) ||
        !nonNegative(p.sigma3))
        throw std::invalid_argument("friction: sigma0 must be > 0 and sigma1..3 >= 0");
    if (!nonNegative(p.dynamicCoefficient) || !(p.staticCoefficient >= p.dynamicCoefficient))
        throw std::invalid_argument("friction: need 0 <= mu_d <= mu_s");
    if (!positive(p.stribeckVelocity) || !positive(p.exciterMassKg))
        throw std::invalid_argument("friction: Stribeck velocity and mass must be > 0");
    if (!(p.breakAway > 0.0 && p.breakAway < 1.0))
        throw std::invalid_argument("friction: break-away fraction must lie in (0, 1)");
    if (p.maxIterations < 1 || p.maxIterations > 1000)
        throw std::invalid_argument("friction: maxIterations must lie in [1, 1000]");
    if (!nonNegative(p.tolerance) || !nonNegative(p.newtonStepTolerance))
        throw std::invalid_argument(
            "friction: tolerance and newtonStepTolerance must be finite and >= 0");
    params_ = p;
    resonator_.configure(std::move(modes), std::move(gains));
    chooseKernel();
}

template <typename Real>
void ElastoPlasticFrictionT<Real>::prepare(double fs) {
    T_ = 1.0 / fs;
    resonator_.prepare(fs);
    // Exciter with the drive spring k and damper c taken at n+1 (first-order hold as elsewhere):
    //   [1 + T^2 k/6M, T^2 c/6M; T k/2M, 1 + T c/2M] [x1; v1] = [r1 - s1 F; r2 - s2 F]
    // with s1 = T^2/6M, s2 = T/2M; so x1 = X - px F and v1 = V - pv F.
    const double T = T_, M = params_.exciterMassKg, k = params_.driveStiffness,
                 c = params_.driveDamping;
    const double m11 = 1.0 + T * T * k / (6.0 * M), m12 = T * T * c / (6.0 * M),
                 m21 = T * k / (2.0 * M), m22 = 1.0 + T * c / (2.0 * M);
    const double det = m11 * m22 - m12 * m21;
    const double s1 = T * T / (6.0 * M), s2 = T / (2.0 * M);
    px_ = (m22 * s1 - m12 * s2) / det;
    pv_ = (m11 * s2 - m21 * s1) / det;
    // The prediction without a new friction force: the old net force H = (external - friction)
    // at n held, the external force E at n+1, r1 = x + T v + T^2 (H / 3M + E / 6M) and
    // r2 = v + T (H + E) / 2M solved through the matrix above, as fixed coefficients.
    const double h1 = T * T / (3.0 * M), e1 = s1, h2 = s2, e2 = s2;
    xX_ = m22 / det;
    xV_ = (m22 * T - m12) / det;
    xH_ = (m22 * h1 - m12 * h2) / det;
    xE_ = (m22 * e1 - m12 * e2) / det;
    vX_ = -m21 / det;
    vV_ = (m11 - m21 * T) / det;
    vH_ = (m11 * h2 - m21 * h1) / det;
    vE_ = (m11 * e2 - m21 * e1) / det;
    kd_ = pv_ + resonator_.mobility(0);
    stiffPlusDamp_ = params_.sigma0 + params_.sigma1 / T;
    dampOverT_ = params_.sigma1 / T;
    stiffTPlusDamp_ = params_.sigma0 * T + params_.sigma1;
    invStribeck_ = 1.0 / params_.stribeckVelocity;
    minusTwoOverVs_ = -2.0 * invStribeck_;
    pMax_ = 1e18 / T;
    d0_ = 1.0 + kd_ * params_.sigma2 + kd_ * stiffTPlusDamp_;
    d1_ = (1.0 + kd_ * params_.sigma2) * T;
    zssPerN_ = params_.dynamicCoefficient / params_.sigma0;
    zssDiffPerN_ = (params_.staticCoefficient - params_.dynamicCoefficient) / params_.sigma0;
    zbaPerN_ = params_.breakAway * params_.dynamicCoefficient / params_.sigma0;
    chooseKernel();
    reset(0);
}

template <typename Real>
void ElastoPlasticFrictionT<Real>::reset(std::uint64_t seed) noexcept {
    resonator_.reset();
    rng_.setSeed(seed);
    z_ = v_ = force_ = exciterX_ = exciterV_ = lastExternal_ = p_ = pPrev_ = pPrev2_ = 0;
    stats_ = FrictionSolveStats{};
}

template <typename Real>
inline double ElastoPlasticFrictionT<Real>::alphaOf(double z, double v, double zss,
                                                    double zba) const noexcept {
    if (v == 0.0 || (z > 0) != (v > 0)) return 0.0; // opposite signs: elastic only
    const double az = std::fabs(z), ass = std::fabs(zss);
    if (az <= zba) return 0.0;
    if (az >= ass) return 1.0;
    const double t = 2.0 * (az - 0.5 * (ass + zba)) / (ass - zba); // in (-1, 1)
    if (params_.libmFunctions) return 0.5 * std::sin(0.5 * kPi * t) + 0.5;
    return 0.5 * frictionSinHalfPi(t) + 0.5;
}

template <typename Real>
[[gnu::always_inline]] inline typename ElastoPlasticFrictionT<Real>::Pass
ElastoPlasticFrictionT<Real>::passAt(const SolveInput& in, double p) const noexcept {
    // The plain pass with the plastic factor fixed at p: d = 1 + T p (>= 1), the bristle
    // z1 = (z0 + T v1) / d and the force F = sC / d + dC + (ST / d + sigma2) v1 (sC = (sigma0 +
    // sigma1 / T) z0, dC = noise - sigma1 z0 / T, ST = sigma0 T + sigma1), whose coupling
    // v1 = vRelPred - kd F has the closed-form root v1 = (n0 + n1 p) / (d0 + d1 p) (numerator and
    // denominator multiplied by d: n0 = A - kd sC, n1 = A T, d0 = B + kd ST, d1 = B T with
    // A = vRelPred - kd dC, B = 1 + kd sigma2).
    Pass x;
    x.invD = 1.0 / (1.0 + T_ * p);
    x.invDen = 1.0 / (d0_ + d1_ * p);
    x.v = (in.n0 + in.n1 * p) * x.invDen;
    x.z = (in.z0 + T_ * x.v) * x.invD;
    return x;
}

template <typename Real>
template <bool Libm>
[[gnu::always_inline]] inline typename ElastoPlasticFrictionT<Real>::Plastic
ElastoPlasticFrictionT<Real>::plasticRate(const SolveInput& in, double v, double z) const noexcept {
    // The same alpha as the fixed-point pass: the larger of alpha(z0, v) and alpha(z, v), i.e.
    // alpha at the candidate of v's sign with the larger |z| (0 when neither has v's sign or
    // the candidate is within the break-away). With s = sgn(v), a candidate of v's sign has
    // s z > 0 and the other sign s z <= 0 <= z_ba, so the candidate is the larger of s z0 and
    // s z, and it counts when it exceeds z_ba (z0 on a tie, as alphaOf's max).
    if (v == 0.0) return {0.0, 0.0, 0.0};
    const double sgn = v > 0.0 ? 1.0 : -1.0;
    const double s0 = sgn * in.z0, s1 = sgn * z;
    const bool trial = s1 > s0; // z_c is the trial's z
    const double az = trial ? s1 : s0;
    if (!(az > in.zba)) return {0.0, 0.0, 0.0};
    // |z_ss(v)| = (f_c + (f_s - f_c) e) / sigma0, e = exp(-(v / v_s)^2) (Stribeck).
    const double u = v * invStribeck_;
    const double e = Libm ? std::exp(-u * u) : frictionExpNeg(-u * u);
    const double ass = in.zssC + in.zssD * e;
    if (!(ass > 0.0)) return {0.0, 0.0, 0.0}; // z_ss = 0: alpha is taken as 0 (as alphaOf)
    const double dAss = minusTwoOverVs_ * u * (in.zssD * e); // d|z_ss| / dv
    const double invAss = 1.0 / ass;
    double a = 1.0, daDz = 0.0, daDass = 0.0;
    if (az < ass) {
        // raised sine in t = 2 (|z| - (|z_ss| + z_ba) / 2) / (|z_ss| - z_ba) in (-1, 1)
        const double invW = 1.0 / (ass - in.zba);
        const double t = 2.0 * (az - 0.5 * (ass + in.zba)) * invW;
        const double sn = Libm ? std::sin(0.5 * kPi * t) : frictionSinHalfPi(t);
        a = 0.5 * sn + 0.5;
        // da/dt = (pi / 4) cos(pi t / 2) >= 0 on [-1, 1]. The cosine is its own polynomial,
        // evaluated beside the sine: taken as sqrt(1 - sin^2) it waited for the sine and a square
        // root, on the chain of dependent operations that sets a sample's time (only the Newton
        // step uses derivatives: their rounding moves the solution by far less than the stop's
        // tolerance)
        const double cs = Libm ? std::cos(0.5 * kPi * t) : frictionCosHalfPi(t);
        const double dadt = 0.25 * kPi * std::max(0.0, cs);
        daDz = dadt * 2.0 * invW;          // d a / d|z|
        daDass = -dadt * (1.0 + t) * invW; // d a / d|z_ss|
    }
    const double r = std::fabs(v) * invAss; // |v| / |z_ss|
    // (capped at pMax_, where T p ~ 1e18 leaves z1 = (z0 + T v1) / (1 + T p) at 0 to double
    // precision: |z_ss| can underflow towards 0 with mu_d = 0 at high speed, and p with it to inf;
    // the derivatives are then not finite, and the step falls back to the bracket)
    const double p = a * r < pMax_ ? a * r : pMax_;
    const double dv = sgn * a * invAss + (r * daDass - p * invAss) * dAss;
    const double dz = trial ? r * daDz * sgn : 0.0;
    return {p, dv, dz};
}

template <typename Real>
double ElastoPlasticFrictionT<Real>::lastSolveResidual() const noexcept {
    const SolveInput& in = in_;
    if (!(in.zssC > 0.0 || in.zssD > 0.0)) return 0.0;
    const Plastic P = params_.libmFunctions ? plasticRate<true>(in, in.vOut, in.zOut)
                                            : plasticRate<false>(in, in.vOut, in.zOut);
    const Pass x = passAt(in, P.p);
    const double vs = params_.stribeckVelocity;
    return std::max(std::fabs(x.v - in.vOut) / std::max(std::fabs(x.v), vs),
                    std::fabs(x.z - in.zOut) / std::max(std::fabs(x.z), T_ * vs));
}

template <typename Real>
template <bool Libm>
[[gnu::always_inline]] inline typename ElastoPlasticFrictionT<Real>::Pass
ElastoPlasticFrictionT<Real>::solveNewton(const SolveInput& in, double vRelPred, int& passesOut,
                                          bool& convergedOut) noexcept {
    int passes = 0;
    bool converged = false;
    // Newton on the plastic rate p. A plain pass with the plastic factor fixed at p is
    // psi(p) = (v1, z1) (passAt, with d = 1 + T p); the solution is the fixed point
    // p = P(psi(p)), P = plasticRate. g(p) = P(psi(p)) - p is continuous, g(0) >= 0 and g < 0
    // for large p (P(psi(p)) stays bounded as psi(p) tends to z1 = 0), so a root lies in
    // [lo, hi]; Newton steps with g' = grad P . psi'(p) - 1 stay inside the bracket or are
    // replaced by a bisection (or, before an upper end is known, by the plain pass p <- P).
    const double T = T_, tol = params_.tolerance, stepTol = params_.newtonStepTolerance;
    const double vScale = params_.stribeckVelocity, zScale = T * params_.stribeckVelocity;
    // Warm start: the last three samples' p extrapolated by a parabola (p varies smoothly while
    // slipping; 0 while sticking). On the creak, with the tight stop (newtonStepTolerance 0), it
    // leaves 1.99 evaluations a sample against 2.06 from the last two samples' line. The first
    // step moves v and z (relative) by at most 1e-3 on ~92 % of the samples and by at most 1e-4
    // on ~52 % (the shipped stop at 1e-3 takes 1.08 evaluations a sample, at 1e-4 1.48).
    double pk = params_.warmStart ? std::max(0.0, 3.0 * (p_ - pPrev_) + pPrev2_)
                                  : plasticRate<Libm>(in, vRelPred, in.z0).p;
    // lo: the largest trial with g > 0 (-1 before one: g(0) >= 0 anyway); hi: the smallest
    // with g < 0. The root lies in [max(lo, 0), hi].
    double lo = -1.0, hi = HUGE_VAL;
    double lastStep = 0.0;
    Pass x = passAt(in, pk);
    while (true) {
        const Plastic P = plasticRate<Libm>(in, x.v, x.z);
        ++passes;
        const double g = P.p - pk;
        if (g == 0.0) { // pk is a fixed point (a sticking sample: p = 0 = P)
            converged = true;
            break;
        }
        if (g > 0.0)
            lo = pk;
        else
            hi = pk;
        // psi'(p): dv/dp = (n1 - d1 v) / (d0 + d1 p), dz/dp = T (dv/dp - z) / d.
        const double dvdp = (in.n1 - d1_ * x.v) * x.invDen;
        const double dzdp = T * (dvdp - x.z) * x.invD;
        const double gp = P.dv * dvdp + P.dz * dzdp - 1.0;
        double next = pk - g / gp;
        if (next < 0.0) next = 0.0; // (p >= 0; a NaN step fails the bracket test below)
        if (!(next > lo && next < hi)) next = hi < HUGE_VAL ? 0.5 * (std::max(lo, 0.0) + hi) : P.p;
        const double step = std::fabs(next - pk), lastStepBefore = lastStep;
        lastStep = step;
        pk = next;
        const double vb = x.v, zb = x.z;
        x = passAt(in, pk);
        // Converged when the step was at most newtonStepTolerance (Newton's error after it is of
        // the order of its square, see FrictionParams), or when the error left in v and z,
        // estimated from the step as below, is at most tol, relative to max(|v|, v_s) and
        // max(|z|, T v_s): the plain passes' criterion. The step's test comes first: it decides
        // almost every sample (1.08 evaluations a sample on the creak), and the estimate's two
        // divisions and its branch are then left out of the sample's chain of operations (the
        // same decision either way: an "or" of the two tests).
        const double moveV = std::fabs(x.v - vb), moveZ = std::fabs(x.z - zb);
        const double scaleV = std::max(std::fabs(x.v), vScale),
                     scaleZ = std::max(std::fabs(x.z), zScale);
        if (moveV <= stepTol * scaleV && moveZ <= stepTol * scaleZ) {
            converged = true;
            break;
        }
        // Contraction of this step against the last one: the error left after a step of a
        // sequence contracting by theta < 1 is at most theta / (1 - theta) times the step (for
        // Newton far less: about theta^2 times it; a pass that moves by at most tol leaves an
        // error of about theta / (1 - theta) tol, theta up to ~0.5 there). With no earlier step,
        // factor 1: the fixed-point criterion itself (a pass that moves by at most tol).
        const double theta = step / lastStepBefore; // (0 / 0 or x / 0 before a step: factor 1)
        const double factor = theta < 0.5 ? theta / (1.0 - theta) : 1.0;
        if (factor * moveV <= tol * scaleV && factor * moveZ <= tol * scaleZ) {
            converged = true;
            break;
        }
        if (passes >= params_.maxIterations) break;
    }
    pPrev2_ = pPrev_;
    pPrev_ = p_;
    p_ = pk;
    passesOut = passes;
    convergedOut = converged;
    return x;
}

template <typename Real>
typename ElastoPlasticFrictionT<Real>::PassesResult
ElastoPlasticFrictionT<Real>::solvePasses(double vRelPred, double z0, double noise, double fc,
                                          double fs, double zba) const noexcept {
    // The fixed-point passes (newton = false; the reference). With the plastic factor
    // alpha / z_ss taken at a trial state (vp, zp), z1 = (z0 + T v1) / d with
    // d = 1 + T vp alpha / z_ss >= 1 (vp / z_ss >= 0): F is linear in v1 and the coupling
    // v1 = vRelPred - kd F has a closed-form root. Passes refine the trial, starting from the
    // previous sample's relative velocity (warm start), until a pass moves v1 and z1 by at most
    // `tolerance` relative to max(|v1|, v_s) and max(|z1|, T v_s), at most maxIterations passes.
    // alpha is taken at the larger of its values at z0 and at the trial z1, so a stiff bristle
    // cannot overshoot z_ss within a sample (with alpha = 1, z1 is a weighted mean of z0 and
    // z_ss). The force applied is exactly the one the root was solved with.
    const double T = T_;
    const double vScale = params_.stribeckVelocity, zScale = T * params_.stribeckVelocity;
    const double tol = params_.tolerance;
    double v1 = params_.warmStart ? v_ : vRelPred, z1 = 0.0, force = 0.0, zp = z0;
    int passes = 0, plain = 0; // plain: passes since the last extrapolation
    bool converged = false;
    double vBefore = 0.0, zBefore = 0.0; // the trial of the previous pass
    while (passes < params_.maxIterations) {
        const double vp = v1;
        // alpha is the larger of its values at z0 and at the trial zp. alphaOf is 0 for a z of
        // the other sign than vp or with |z| <= z_ba, and non-decreasing in |z| otherwise (a
        // raised sine between z_ba and |z_ss|, then 1): the larger value is the one at the
        // candidate of vp's sign with the larger |z|, so one alphaOf (at most one sine) gives it.
        // The Stribeck exp is only needed when that candidate is past the break-away (sticking
        // samples skip it). Same values as evaluating both, in fewer operations.
        const bool ok0 = vp != 0.0 && (z0 > 0) == (vp > 0);
        const bool okp = vp != 0.0 && (zp > 0) == (vp > 0);
        double zc = 0.0;
        if (ok0 && okp)
            zc = std::fabs(zp) > std::fabs(z0) ? zp : z0;
        else if (ok0 || okp)
            zc = ok0 ? z0 : zp;
        double a = 0.0, zss = 0.0;
        if ((ok0 || okp) && std::fabs(zc) > zba) {
            const double sgn = vp >= 0.0 ? 1.0 : -1.0;
            const double vs = vp / params_.stribeckVelocity;
            const double stribeck =
                params_.libmFunctions ? std::exp(-vs * vs) : frictionExpNeg(-vs * vs);
            zss = sgn * (fc + (fs - fc) * stribeck) / params_.sigma0;
            if (zss != 0.0) a = alphaOf(zc, vp, zss, zba);
        }
        // (1/d computed once; sigma0 + sigma1 / T and sigma0 T + sigma1 precomputed: the same
        // quantities as sigma0 z0 / d + sigma1 (z0 / d - z0) / T and sigma0 T / d + sigma1 / d,
        // rounded differently)
        const double invD = a > 0.0 ? 1.0 / (1.0 + T * vp * a / zss) : 1.0;
        const double zd = z0 * invD;
        const double constant = stiffPlusDamp_ * zd - dampOverT_ * z0 + noise;
        const double slope = stiffTPlusDamp_ * invD + params_.sigma2;
        v1 = (vRelPred - kd_ * constant) / (1.0 + kd_ * slope);
        z1 = (z0 + T * v1) * invD;
        force = constant + slope * v1;
        ++passes;
        if (std::fabs(v1 - vp) <= tol * std::max(std::fabs(v1), vScale) &&
            std::fabs(z1 - zp) <= tol * std::max(std::fabs(z1), zScale)) {
            converged = true;
            break;
        }
        // Aitken's delta-squared on each of v and z after two plain passes: the passes converge
        // linearly (ratios ~0.1 to 0.5 while slipping), the extrapolation skips most of them.
        // Only the trial changes: convergence is still judged on a plain pass (its result equals
        // its trial), so the solution is the same fixed point.
        double vNext = v1, zNext = z1;
        if (params_.extrapolate && ++plain >= 2) {
            const double dv0 = vp - vBefore, dv1 = v1 - vp, dz0 = zp - zBefore, dz1 = z1 - zp;
            const double denV = dv1 - dv0, denZ = dz1 - dz0;
            if (denV != 0.0 && denZ != 0.0) {
                vNext = v1 - dv1 * dv1 / denV;
                zNext = z1 - dz1 * dz1 / denZ;
                plain = 0;
            }
        }
        vBefore = vp;
        zBefore = zp;
        v1 = vNext;
        zp = zNext;
    }
    return {v1, z1, force, passes, converged};
}

template <typename Real>
template <bool Libm, bool Wide>
[[gnu::always_inline]] inline double
ElastoPlasticFrictionT<Real>::processBody(double normal, double drive, double anchorX,
                                          double anchorV, double roughness) noexcept {
    const double T = T_;
    const double N = std::max(0.0, normal);
    // Predictions without a new friction force (old net force held, the external force at n+1:
    // the drive and the drive spring/damper's pull, taken implicitly; see prepare()).
    const double k = params_.driveStiffness, c = params_.driveDamping;
    const double external = drive + k * anchorX + c * anchorV;
    const double held = lastExternal_ - force_;
    const double xePred = xX_ * exciterX_ + xV_ * exciterV_ + xH_ * held + xE_ * external;
    const double vePred = vX_ * exciterX_ + vV_ * exciterV_ + vH_ * held + vE_ * external;
    resonator_.template predictInline<Wide>(); // (predict(), the pass inline)
    const double vRelPred = vePred - resonator_.predictedVelocity(0);

    // No load, no contact: no friction at all (z1 = 0, F = 0). Without a Newton solve below
    // there is no residual to report (lastSolveResidual() gives 0).
    if (trackResidual_) in_.zssC = in_.zssD = 0.0;
    double force = 0.0, z1 = 0.0;
    if (N > 0.0) {
        // Roughness noise acts only while the surfaces are pressed together (and, at the
        // caller's say, rubbed: roughness 0 draws nothing).
        const double noise = roughness != 0.0 ? roughness * (params_.sigma3 * rng_.bipolar()) : 0.0;
        const double z0 = z_;
        int passes = 0;
        bool converged = false;
        if (params_.newton) {
            // Shipped: Newton on the plastic rate (solveNewton); the output is the plain pass at
            // the final p, whose force is the one its v1 was solved with. The relative velocity at
            // n+1 solves h(v) = v - vRelPred + kd F(v) = 0 with the bristle integrated by backward
            // Euler, z1 = z0 + T v1 (1 - alpha z1 / z_ss) (see passAt and solveNewton).
            SolveInput in;
            in.z0 = z0;
            in.sC = stiffPlusDamp_ * z0;
            in.dC = -dampOverT_ * z0 + noise;
            const double A = vRelPred - kd_ * in.dC;
            in.n0 = A - kd_ * in.sC;
            in.n1 = A * T;
            in.zssC = N * zssPerN_;
            in.zssD = N * zssDiffPerN_;
            in.zba = N * zbaPerN_;
            const Pass x = solveNewton<Libm>(in, vRelPred, passes, converged);
            z1 = x.z;
            force = in.sC * x.invD + in.dC + (stiffTPlusDamp_ * x.invD + params_.sigma2) * x.v;
            if (trackResidual_) {
                in.vOut = x.v;
                in.zOut = z1;
                in_ = in;
            }
        } else {
            const double fc = params_.dynamicCoefficient * N, fs = params_.staticCoefficient * N;
            const PassesResult r =
                solvePasses(vRelPred, z0, noise, fc, fs, params_.breakAway * fc / params_.sigma0);
            z1 = r.z;
            force = r.force;
            passes = r.passes;
            converged = r.converged;
        }
        ++stats_.samples;
        stats_.passes += static_cast<std::uint64_t>(passes);
        if (!converged) ++stats_.capHits;
        stats_.maxPassesInOneSample = std::max(stats_.maxPassesInOneSample, passes);
    }
    // Commit: friction acts against the exciter's relative motion, with it on the resonator.
    exciterX_ = xePred - px_ * force;
    exciterV_ = vePred - pv_ * force;
    resonator_.commit(0, force);
    z_ = snapToZero(z1);
    v_ = exciterV_ - resonator_.contactVelocity();
    force_ = force;
    lastExternal_ = external - k * exciterX_ - c * exciterV_;
    return resonator_.velocity(0);
}

template <typename Real>
template <bool Libm>
double ElastoPlasticFrictionT<Real>::kernelGeneric(ElastoPlasticFrictionT& f, double normal,
                                                   double drive, double anchorX, double anchorV,
                                                   double roughness) noexcept {
    return f.processBody<Libm, false>(normal, drive, anchorX, anchorV, roughness);
}

// The same code compiled with VEX encoding (three-operand scalar instructions: fewer register
// copies). No FMA: every operation rounds as in kernelGeneric, so the samples are identical.
template <typename Real>
template <bool Libm>
[[gnu::target("avx")]] double
ElastoPlasticFrictionT<Real>::kernelAvx(ElastoPlasticFrictionT& f, double normal, double drive,
                                        double anchorX, double anchorV, double roughness) noexcept {
    return f.processBody<Libm, true>(normal, drive, anchorX, anchorV, roughness);
}

template <typename Real>
void ElastoPlasticFrictionT<Real>::chooseKernel() noexcept {
    const bool avx = avxAllowed_ && simdAllowsAvx();
    if (params_.libmFunctions)
        kernel_ = avx ? &kernelAvx<true> : &kernelGeneric<true>;
    else
        kernel_ = avx ? &kernelAvx<false> : &kernelGeneric<false>;
}

template <typename Real>
void ElastoPlasticFrictionT<Real>::allowAvx(bool on) noexcept {
    avxAllowed_ = on;
    resonator_.allowAvx(on);
    chooseKernel();
}

template <typename Real>
bool ElastoPlasticFrictionT<Real>::usesAvx() const noexcept {
    return kernel_ == &kernelAvx<true> || kernel_ == &kernelAvx<false>;
}

template class ElastoPlasticFrictionT<double>;
template class ElastoPlasticFrictionT<float>;

} // namespace underfoot::engine
