// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The sensor log of a live trial: raw shoe frames, step events (with the GRF the player chose)
/// and gyroscope samples, one CSV file a trial references (docs/reference/sensors.md, "Sensor
/// log").
/// Written by the one consumer of the sources' SPSC queues (in a live session the live player's
/// sensor-log thread, app/wiring/Players.cpp), never on the audio thread. Long format, one row per
/// record, time on the sensor clock relative to the log's start:
///
///     time_s,kind,device_ms,index,lh,lt,rh,rt,foot,part,strength,derivative_per_s,bank_index,
///     gain,start_sample,limb,angular_velocity_dps,sequence
///
/// kind is "frame", "step" (a detected step), "grf" (a step the player started: bank_index,
/// gain, start_sample) or "gyro"; cells a kind does not use are empty.
#include "engine/control/GyroFrame.h"
#include "engine/control/StepDetector.h"
#include "engine/control/StepGrfPlayer.h"
#include "engine/io/sensors/ShoeFrame.h"

#include <cstdint>
#include <cstdio>
#include <string>

namespace underfoot::engine {

/// Appends sensor records to a CSV file.
class SensorLogWriter {
  public:
    /// Creates (truncates) `path`; times are written relative to `originS` (sensor clock).
    /// Throws std::runtime_error naming the file when it cannot be created.
    SensorLogWriter(const std::string& path, double originS);
    ~SensorLogWriter();
    SensorLogWriter(const SensorLogWriter&) = delete;
    SensorLogWriter& operator=(const SensorLogWriter&) = delete;

    void write(const ShoeFrame& frame);
    void write(const StepEvent& step);
    void write(const StepPlayback& playback);
    void write(const GyroSample& sample);
    /// Flushes to disk; throws std::runtime_error naming the file on a write error.
    void flush();
    /// Rows written.
    std::uint64_t rows() const noexcept { return rows_; }
    const std::string& path() const noexcept { return path_; }

  private:
    std::string path_;
    double originS_;
    std::FILE* file_ = nullptr;
    std::uint64_t rows_ = 0;
};

} // namespace underfoot::engine
