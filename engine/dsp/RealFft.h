// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A double-precision real FFT of one size (FFTW r2c forward, c2r inverse) that owns its aligned
/// buffers and plans. FFTW's planner is not thread-safe (only fftw_execute is), and the analysis
/// code runs on worker threads (the console's palette, power and export workers): every plan of
/// either precision is made and destroyed under fftwPlannerMutex(). Never on the audio thread.
#include <fftw3.h>

#include <mutex>

namespace underfoot::engine {

/// The one lock around FFTW plan creation and destruction (fftw_* and fftwf_*).
std::mutex& fftwPlannerMutex();

class RealFft {
  public:
    /// n >= 2 real samples; spectrum() has n / 2 + 1 bins. Throws std::bad_alloc.
    explicit RealFft(int n);
    ~RealFft();
    RealFft(const RealFft&) = delete;
    RealFft& operator=(const RealFft&) = delete;

    int size() const noexcept { return n_; }
    double* time() noexcept { return time_; }
    fftw_complex* spectrum() noexcept { return freq_; }
    /// time() -> spectrum() (unnormalised).
    void forward() noexcept { fftw_execute(forward_); }
    /// spectrum() -> time(), scaled by n (unnormalised, as FFTW; the spectrum is overwritten).
    void inverse() noexcept { fftw_execute(inverse_); }

  private:
    int n_;
    double* time_ = nullptr;
    fftw_complex* freq_ = nullptr;
    fftw_plan forward_ = nullptr, inverse_ = nullptr;
};

} // namespace underfoot::engine
