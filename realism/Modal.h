// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// High-resolution modal estimate of a struck solid: frequencies, decays and gains of a sum of
/// exponentially damped sinusoids, by the matrix pencil method (Hua & Sarkar 1990, IEEE Trans.
/// ASSP 38(5)), with LAPACK's SVD, eigenvalue and least-squares drivers.
///
/// x[n] ~ sum_k a_k e^{-sigma_k n / fs} cos(2 pi f_k n / fs + phi_k). The Hankel matrix of the
/// signal is reduced to its 2K strongest singular directions; the poles z = e^{(-sigma + i 2 pi
/// f) / fs} are the eigenvalues of the shifted pencil of those directions, and the gains follow
/// from least squares on the Vandermonde matrix of the poles. Used by `underfoot fit --modes`
/// on recorded strikes as the starting point of a solid's modal parameters.
#include <string>
#include <vector>

namespace underfoot::realism {

struct Mode {
    double frequencyHz = 0; ///< damped frequency
    double decayPerS = 0;   ///< sigma: the envelope falls as e^{-sigma t}
    double t60S = 0;        ///< time to fall 60 dB: ln(1000) / sigma
    double amplitude = 0;   ///< a_k, in the signal's units (peak of the cosine at n = 0)
    double phase = 0;       ///< phi_k, radians
};

struct ModalOptions {
    int modes = 8;         ///< K real modes sought (model order 2K, plus `extraOrder`)
    int extraOrder = 8;    ///< extra poles that soak up noise and are discarded
    int maxSamples = 1536; ///< the analysed segment is cut to this many samples
    double minHz = 20;     ///< modes outside [minHz, maxHz] are dropped
    double maxHz = 20000;
};

/// The modes of x (sampled at fs), strongest first; growing or out-of-band poles are left out.
/// Throws std::invalid_argument for a too-short segment, non-finite samples, fs <= 0 or an
/// order that does not fit the segment.
std::vector<Mode> matrixPencilModes(const std::vector<double>& x, double fs,
                                    const ModalOptions& o = {});

/// The modes of one recorded footstep: the segment from the envelope peak of the strongest step
/// on, up to o.maxSamples at 48 kHz. Throws engine::FileError for an unreadable file and
/// std::invalid_argument when it has no step.
std::vector<Mode> modesOfRecording(const std::string& path, const ModalOptions& o = {});

} // namespace underfoot::realism
