// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/dsp/RealFft.h"

#include <new>

namespace underfoot::engine {

std::mutex& fftwPlannerMutex() {
    static std::mutex m;
    return m;
}

RealFft::RealFft(int n) : n_(n) {
    if (n < 2) throw std::bad_alloc();
    std::lock_guard<std::mutex> lock(fftwPlannerMutex());
    time_ = fftw_alloc_real(static_cast<std::size_t>(n));
    freq_ = fftw_alloc_complex(static_cast<std::size_t>(n / 2 + 1));
    if (time_ && freq_) {
        forward_ = fftw_plan_dft_r2c_1d(n, time_, freq_, FFTW_ESTIMATE);
        inverse_ = fftw_plan_dft_c2r_1d(n, freq_, time_, FFTW_ESTIMATE);
    }
    if (!forward_ || !inverse_) {
        if (forward_) fftw_destroy_plan(forward_);
        if (inverse_) fftw_destroy_plan(inverse_);
        fftw_free(time_);
        fftw_free(freq_);
        throw std::bad_alloc();
    }
}

RealFft::~RealFft() {
    std::lock_guard<std::mutex> lock(fftwPlannerMutex());
    fftw_destroy_plan(forward_);
    fftw_destroy_plan(inverse_);
    fftw_free(time_);
    fftw_free(freq_);
}

} // namespace underfoot::engine
