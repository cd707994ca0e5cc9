// SPDX-License-Identifier: GPL-3.0-or-later
#include "realism/Modal.h"

#include "realism/Descriptors.h"

#include <fmt/core.h>
#include <lapacke.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

namespace underfoot::realism {
namespace {

std::vector<double> zeros(int n) {
    return std::vector<double>(std::size_t(n));
}

void lapackCheck(lapack_int info, const char* what) {
    if (info != 0)
        throw std::invalid_argument(
            fmt::format("modal estimate: {} failed (LAPACK info {})", what, info));
}

/// Solves A X = B (A m x n column-major, m >= n, B m x nrhs) in least squares, minimum norm,
/// by LAPACK's SVD-based dgelsd; X is left in the top n rows of B.
void leastSquares(int m, int n, int nrhs, std::vector<double> a, std::vector<double>& b,
                  const char* what) {
    std::vector<double> s(zeros(std::min(m, n)));
    lapack_int rank = 0;
    lapackCheck(LAPACKE_dgelsd(LAPACK_COL_MAJOR, m, n, nrhs, a.data(), m, b.data(), m, s.data(),
                               -1.0, &rank),
                what);
}

} // namespace

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
    const int rows = len - pencil, cols = pencil + 1;
    // Hankel matrix (column-major, as LAPACK wants it) and its thin SVD: only V^T is used.
    std::vector<double> hankel(zeros(rows * cols));
    for (int j = 0; j < cols; ++j)
        for (int i = 0; i < rows; ++i)
            hankel[std::size_t(j) * std::size_t(rows) + std::size_t(i)] = input[std::size_t(i + j)];
    const int k = std::min(rows, cols);
    std::vector<double> sv(zeros(k)), u(zeros(rows * k)), vt(zeros(k * cols));
    lapackCheck(LAPACKE_dgesdd(LAPACK_COL_MAJOR, 'S', rows, cols, hankel.data(), rows, sv.data(),
                               u.data(), rows, vt.data(), k),
                "SVD of the Hankel matrix");
    // v = V's first `order` columns; v1 its top `pencil` rows, v2 its bottom ones (one lower).
    // v1 a = v2 in least squares (minimum norm, SVD-based: v1 may be rank-deficient).
    std::vector<double> v1(zeros(pencil * order)), a(zeros(pencil * order));
    for (int c = 0; c < order; ++c)
        for (int r = 0; r < pencil; ++r) {
            v1[std::size_t(c) * std::size_t(pencil) + std::size_t(r)] =
                vt[std::size_t(r) * std::size_t(k) + std::size_t(c)];
            a[std::size_t(c) * std::size_t(pencil) + std::size_t(r)] =
                vt[std::size_t(r + 1) * std::size_t(k) + std::size_t(c)];
        }
    leastSquares(pencil, order, order, v1, a, "the pencil's least squares");
    // The poles: eigenvalues of the order x order solution (the top rows of `a`).
    std::vector<double> pencilMatrix(zeros(order * order));
    for (int c = 0; c < order; ++c)
        for (int r = 0; r < order; ++r)
            pencilMatrix[std::size_t(c) * std::size_t(order) + std::size_t(r)] =
                a[std::size_t(c) * std::size_t(pencil) + std::size_t(r)];
    std::vector<double> re(zeros(order)), im(zeros(order));
    double unusedVector = 0;
    lapackCheck(LAPACKE_dgeev(LAPACK_COL_MAJOR, 'N', 'N', order, pencilMatrix.data(), order,
                              re.data(), im.data(), &unusedVector, 1, &unusedVector, 1),
                "eigenvalues of the pencil");

    // Gains: least squares x[n] = sum_k h_k z_k^n over the whole segment, in real arithmetic:
    // a conjugate pair r e^{+-i theta} becomes the columns r^n cos(n theta), r^n sin(n theta)
    // (its twin with negative imaginary part is skipped), a real pole one column r^n. A pole
    // whose powers leave the range of a double (growing fast) gets no column; it is dropped
    // below anyway.
    struct Column {
        std::complex<double> pole;
        bool pair;
    };
    std::vector<Column> columns;
    for (int c = 0; c < order; ++c) {
        const std::complex<double> z(re[std::size_t(c)], im[std::size_t(c)]);
        if (z.imag() < 0) continue;
        if (!std::isfinite(std::pow(std::abs(z), double(len)))) continue;
        columns.push_back({z, z.imag() > 0});
    }
    int width = 0;
    for (const auto& c : columns) width += c.pair ? 2 : 1;
    std::vector<double> design(zeros(len * width)), rhs(zeros(len));
    for (int i = 0; i < len; ++i) rhs[std::size_t(i)] = input[std::size_t(i)];
    {
        int col = 0;
        for (const auto& c : columns) {
            std::complex<double> p(1.0, 0.0);
            for (int i = 0; i < len; ++i) {
                design[std::size_t(col) * std::size_t(len) + std::size_t(i)] = p.real();
                if (c.pair)
                    design[std::size_t(col + 1) * std::size_t(len) + std::size_t(i)] = p.imag();
                p *= c.pole;
            }
            col += c.pair ? 2 : 1;
        }
    }
    if (width > 0) leastSquares(len, width, 1, design, rhs, "the gains' least squares");

    std::vector<Mode> modes;
    int col = 0;
    for (const auto& c : columns) {
        const auto z = c.pole;
        // x = A r^n cos(n theta) + B r^n sin(n theta) = a r^n cos(n theta + phi) with
        // a = hypot(A, B) and phi = atan2(-B, A).
        const double gainA = rhs[std::size_t(col)],
                     gainB = c.pair ? rhs[std::size_t(col + 1)] : 0.0;
        col += c.pair ? 2 : 1;
        const double arg = std::arg(z), mag = std::abs(z);
        if (!c.pair || !(mag > 0) || mag >= 1) continue; // real, growing or static
        Mode m;
        m.frequencyHz = arg * fs / (2 * std::numbers::pi);
        if (m.frequencyHz < o.minHz || m.frequencyHz > o.maxHz) continue;
        m.decayPerS = -std::log(mag) * fs;
        m.t60S = std::log(1000.0) / m.decayPerS;
        m.amplitude = std::hypot(gainA, gainB);
        m.phase = std::atan2(-gainB, gainA);
        modes.push_back(m);
    }
    std::sort(modes.begin(), modes.end(),
              [](const Mode& p, const Mode& q) { return p.amplitude > q.amplitude; });
    if (modes.size() > std::size_t(o.modes)) modes.resize(std::size_t(o.modes));
    return modes;
}

std::vector<Mode> modesOfRecording(const std::string& path, const ModalOptions& o) {
    AnalysisOptions ao;
    ao.noiseFloorDb = 0; // the matrix pencil sees the recording as it is
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
