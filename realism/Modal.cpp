// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/Modal.h"

#include "realism/Descriptors.h"

#include <Eigen/Dense>
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

namespace underfoot::realism {

std::vector<Mode> matrixPencilModes(const std::vector<double>& input, double fs,
                                    const ModalOptions& o) {
    if (!(fs > 0) || !std::isfinite(fs))
        throw std::invalid_argument(fmt::format("modal estimate: sample rate {} Hz", fs));
    if (o.modes < 1 || o.extraOrder < 0)
        throw std::invalid_argument("modal estimate: at least one mode, no negative extra order");
    const std::size_t n =
        std::min<std::size_t>(input.size(), std::size_t(std::max(o.maxSamples, 0)));
    const int order = 2 * o.modes + o.extraOrder;
    // Pencil parameter L between N/3 and N/2 (Hua & Sarkar): N/3 here.
    const int len = int(n);
    const int pencil = len / 3;
    if (pencil <= order || len - pencil <= order)
        throw std::invalid_argument(
            fmt::format("modal estimate: {} samples are too few for {} poles (need more than {})",
                        len, order, 3 * (order + 1)));
    for (std::size_t i = 0; i < n; ++i)
        if (!std::isfinite(input[i]))
            throw std::invalid_argument(fmt::format("modal estimate: sample {} is not finite", i));
    const int rows = len - pencil;
    Eigen::MatrixXd hankel(rows, pencil + 1);
    for (int i = 0; i < rows; ++i)
        for (int j = 0; j <= pencil; ++j) hankel(i, j) = input[std::size_t(i + j)];
    Eigen::BDCSVD<Eigen::MatrixXd> svd(hankel, Eigen::ComputeThinV);
    const Eigen::MatrixXd v = svd.matrixV().leftCols(order);
    const Eigen::MatrixXd v1 = v.topRows(pencil), v2 = v.bottomRows(pencil);
    const Eigen::MatrixXd a = v1.completeOrthogonalDecomposition().solve(v2);
    const Eigen::VectorXcd poles = Eigen::EigenSolver<Eigen::MatrixXd>(a, false).eigenvalues();

    // Gains: least squares x[n] = sum_k h_k z_k^n over the whole segment.
    Eigen::MatrixXcd vander(len, order);
    for (int k = 0; k < order; ++k) {
        std::complex<double> p(1.0, 0.0);
        for (int i = 0; i < len; ++i) {
            vander(i, k) = p;
            p *= poles(k);
        }
    }
    Eigen::VectorXcd rhs(len);
    for (int i = 0; i < len; ++i) rhs(i) = input[std::size_t(i)];
    const Eigen::VectorXcd h = vander.colPivHouseholderQr().solve(rhs);

    std::vector<Mode> modes;
    for (int k = 0; k < order; ++k) {
        const auto z = poles(k);
        const double arg = std::arg(z), mag = std::abs(z);
        if (arg <= 0 || !(mag > 0) || mag >= 1) continue; // conjugate twin, growing or static
        Mode m;
        m.frequencyHz = arg * fs / (2 * std::numbers::pi);
        if (m.frequencyHz < o.minHz || m.frequencyHz > o.maxHz) continue;
        m.decayPerS = -std::log(mag) * fs;
        m.t60S = std::log(1000.0) / m.decayPerS;
        m.amplitude = 2 * std::abs(h(k)); // the conjugate pole carries the other half
        m.phase = std::arg(h(k));
        modes.push_back(m);
    }
    std::sort(modes.begin(), modes.end(),
              [](const Mode& p, const Mode& q) { return p.amplitude > q.amplitude; });
    if (modes.size() > std::size_t(o.modes)) modes.resize(std::size_t(o.modes));
    return modes;
}

std::vector<Mode> modesOfRecording(const std::string& path, const ModalOptions& o) {
    AnalysisOptions ao;
    const auto x = analysisSignal(engine::readAudioFile(path), ao);
    const auto steps = segmentSteps(x, ao.analysisRateHz, ao);
    if (steps.empty()) throw std::invalid_argument(fmt::format("{}: no step found", path));
    // The strongest step, from its peak sample on.
    std::size_t best = 0;
    float bestPeak = -1;
    for (const auto& s : steps)
        for (std::size_t i = s.begin; i < s.end; ++i)
            if (std::fabs(x[i]) > bestPeak) bestPeak = std::fabs(x[i]), best = i;
    std::vector<double> seg;
    for (std::size_t i = best; i < x.size() && seg.size() < std::size_t(o.maxSamples); ++i)
        seg.push_back(x[i]);
    auto opt = o;
    opt.maxHz = std::min(o.maxHz, 0.95 * 0.5 * engine::readAudioFile(path).sampleRateHz);
    return matrixPencilModes(seg, ao.analysisRateHz, opt);
}

} // namespace underfoot::realism
