// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Synthetic room impulse responses: image-source early reflections in a shoebox room plus a
/// statistically modelled late tail, with a reverberation time per octave band. Seeded.
///
/// Model:
///  - Absorption: uniform on all six surfaces, per octave band, from Eyring's formula solved for
///    the requested T60: alpha_b = 1 - exp(-0.161 V / (S T60_b)) (Kuttruff, "Room Acoustics",
///    5th ed., §5.4). Reflection factor beta_b = sqrt(1 - alpha_b).
///  - Early part: image sources of the shoebox (Allen & Berkley 1979, JASA 65(4):943-950), each
///    with amplitude prod(beta_b) / distance per band, placed with a 16-tap Hann-windowed sinc
///    fractional delay, up to 1.5 x the mixing time t_mix = 20 V / S + 12 ms (Lindau, Kosanke &
///    Weinzierl 2012, JAES 60(11): "Perceptual evaluation of model- and signal-based predictors
///    of the mixing time in binaural room impulse responses"), cross-faded (cos^2) into the tail
///    between t_mix and 1.5 t_mix.
///  - Late part: Gaussian white noise (seeded, one independent sequence per ear) split into nine
///    bands centred on 62.5 Hz x 2^j (the seven octave bands plus one below and one above, which
///    share the T60 of their neighbour) by complementary crossovers (flat over the middle half
///    octave, cos^2 transitions half an octave wide on the band edges; the bands sum to the
///    noise). Each band's short-term RMS is flattened (divided by its running RMS over
///    max(20 ms, 32 periods)) and then multiplied by exp(-6.91 t / T60_b), so the decay measured
///    is the one requested (raw Gaussian band noise scatters a T30 by about +-10 % in the low
///    octaves). Its level is the expected energy density of the image-source response,
///    4 pi c / V per second relative to a direct sound of amplitude 1 / d (Kuttruff §4.1
///    counting argument), so early
///    and late parts join without a step.
///  - Time 0 is the first arrival of the direct sound (propagation delay removed: zero pre-delay,
///  so the
///    zero-latency convolver keeps the dry onset). The IR is scaled so that the direct sound has
///    amplitude 0.5 (-6 dB), leaving room for the floor reflection that arrives almost with it
///    when the source (a footstep) is on the floor; multiply by 2 for a unit-gain direct path.
///  - Stereo: two receivers 18 cm apart (ears) around the listener position.
/// The reverberation time quoted for a room is T_mid, the mean of the 500 Hz and 1 kHz bands
/// (ISO 3382-1). Note that the broadband T60 of a white-spectrum IR follows the high bands, where
/// most of its energy lies.
#include "engine/io/AudioFile.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace underfoot::engine {

inline constexpr int kOctaveBandCount = 7;
/// Octave band centres, Hz (IEC 61260 nominal).
inline constexpr std::array<double, kOctaveBandCount> kOctaveBandCentersHz = {
    125.0, 250.0, 500.0, 1000.0, 2000.0, 4000.0, 8000.0};

struct Point3 {
    double x = 0, y = 0, z = 0; ///< metres; x along the length, y the width, z up from the floor
};

/// A shoebox room with a reverberation time per octave band.
struct RoomSpec {
    std::string name;
    std::string description;
    double lengthM = 7, widthM = 5, heightM = 3;
    std::array<double, kOctaveBandCount> t60Seconds{}; ///< per band of kOctaveBandCentersHz
    Point3 sourceM{};                                  ///< the footstep (near the floor)
    Point3 listenerM{};                                ///< centre of the listener's head
    double earSpacingM = 0.18;
    double speedOfSoundMps = 343.0;

    double volumeM3() const { return lengthM * widthM * heightM; }
    double surfaceM2() const {
        return 2.0 * (lengthM * widthM + lengthM * heightM + widthM * heightM);
    }
    /// Lindau et al. 2012 mixing time, 20 V / S + 12 ms, in seconds.
    double mixingTimeSeconds() const { return 0.020 * volumeM3() / surfaceM2() + 0.012; }
    /// Eyring absorption coefficient of a band that gives its T60.
    double absorption(int band) const;
    /// T_mid: mean of the 500 Hz and 1 kHz T60.
    double midT60Seconds() const { return 0.5 * (t60Seconds[2] + t60Seconds[3]); }
    /// Throws std::invalid_argument when a dimension, a T60 or a position is impossible.
    void validate() const;
};

/// Names of the built-in rooms.
std::vector<std::string> roomPresetNames();
/// A built-in room by name; throws std::invalid_argument listing the names.
RoomSpec roomPreset(const std::string& name);

/// How an IR is rendered.
struct RoomIrOptions {
    double sampleRateHz = 48000.0;
    std::uint64_t seed = 1;
    double lengthSeconds = 0.0; ///< 0: 1.1 x the longest band T60 (the tail ends near -66 dB)
    int channels = 2;           ///< 1 (listener position) or 2 (two ears)
};

/// Renders the room's impulse response (see the model above). Throws std::invalid_argument.
AudioBuffer generateRoomImpulseResponse(const RoomSpec& room, const RoomIrOptions& options = {});

/// Schroeder backward integration (Schroeder 1965, JASA 37:409): the energy decay curve in dB
/// (0 dB at t = 0).
std::vector<double> energyDecayCurveDb(const std::vector<float>& ir);
/// T60 from a least-squares line through the decay curve between fromDb and toDb (T30 by
/// default: -5 to -35 dB, extrapolated to 60 dB; ISO 3382-1). Throws std::invalid_argument when
/// the curve never reaches toDb.
double schroederT60Seconds(const std::vector<float>& ir, double sampleRateHz, double fromDb = -5.0,
                           double toDb = -35.0);

} // namespace underfoot::engine
