// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Helpers shared by the benchmarks (they were copied between bench_live.cpp and bench_reverb.cpp,
// duplicates D3): thread / process CPU clocks, a deterministic noise block, zita-convolver used
// as its author intends, and the per-block timing of engine/render/SceneBench (one method for
// `underfoot bench` and the benchmarks).
#include "engine/io/AudioFile.h"
#include "engine/render/SceneBench.h"

#include <zita-convolver.h>

#include <algorithm>
#include <cstdint>
#include <ctime>
#include <stdexcept>
#include <vector>

namespace underfoot::bench {

inline double threadCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

inline double processCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// n samples of uniform noise in [-0.1, 0.1) from a linear congruential generator (seeded).
inline std::vector<float> noise(std::size_t n, std::uint32_t seed) {
    std::vector<float> x(n);
    for (auto& v : x) {
        seed = seed * 1664525u + 1013904223u;
        v = (static_cast<float>(seed >> 8) / 16777216.0f - 0.5f) * 0.2f;
    }
    return x;
}

/// zita-convolver used as its author intends: one Convproc, mono in, stereo IR out, quantum
/// `block`, non-uniform partitions block..8192 computed in its own worker threads, one quantum of
/// latency. Never destroy one: after a run faster than real time the Debian build's
/// stop_process()/cleanup() waits forever for its worker threads (seen with gdb: workers in
/// Convlevel::main's sem_wait, cleanup() polling); the program's exit ends them.
struct Zita {
    Zita(const engine::AudioBuffer& ir, int block) : block_(block) {
        const auto len = static_cast<unsigned>(ir.frames());
        zita.set_options(Convproc::OPT_VECTOR_MODE); // as our Convolver's stages
        if (zita.configure(1, 2, len, static_cast<unsigned>(block), static_cast<unsigned>(block),
                           8192, 0.0f) != 0)
            throw std::runtime_error("zita configure failed");
        for (int c = 0; c < 2; ++c) {
            std::vector<float> h(len);
            for (unsigned i = 0; i < len; ++i) h[i] = ir.at(i, ir.channels > 1 ? c : 0);
            zita.impdata_create(0, static_cast<unsigned>(c), 1, h.data(), 0, static_cast<int>(len));
        }
        if (zita.start_process(0, SCHED_OTHER) != 0) throw std::runtime_error("zita start failed");
    }
    void block(const float* in, float* l, float* r) {
        std::copy(in, in + block_, zita.inpdata(0));
        // Synchronous: each call waits for the worker threads' partitions due in it, so that
        // running faster than real time measures all of zita's work instead of letting it
        // fall behind (zita stops itself after 5 late cycles in asynchronous mode).
        zita.process(true);
        std::copy(zita.outdata(0), zita.outdata(0) + block_, l);
        std::copy(zita.outdata(1), zita.outdata(1) + block_, r);
    }
    Convproc zita;
    int block_;
};

} // namespace underfoot::bench
