// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// A LiveEngine without a device whose callback body runs on a thread of its own, paced like a
/// sound card (64 frames at 48 kHz, stereo out, no inputs): the live path for tests that need
/// audio time to pass but no server.
#include "engine/scene/LiveEngine.h"

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

namespace underfoot::test {

class PacedOfflineEngine {
  public:
    PacedOfflineEngine() {
        engine::AudioSettings settings;
        settings.sampleRateHz = 48000;
        settings.blockSize = 64;
        engine.openOffline(settings);
        thread_ = std::thread([this] {
            std::vector<std::vector<float>> out(2, std::vector<float>(64));
            std::vector<float*> op;
            for (auto& c : out) op.push_back(c.data());
            const auto start = std::chrono::steady_clock::now();
            for (std::size_t b = 0; running_.load(); ++b) { // 64 / 48000 s per block
                std::this_thread::sleep_until(start + std::chrono::microseconds(b * 4000 / 3));
                engine.processBlock(nullptr, op.data(), 64);
            }
        });
    }
    ~PacedOfflineEngine() { stop(); }
    PacedOfflineEngine(const PacedOfflineEngine&) = delete;
    PacedOfflineEngine& operator=(const PacedOfflineEngine&) = delete;
    /// Stops the callback thread (idempotent).
    void stop() {
        running_ = false;
        if (thread_.joinable()) thread_.join();
    }

    engine::LiveEngine engine;

  private:
    std::atomic<bool> running_{true};
    std::thread thread_;
};

} // namespace underfoot::test
