// SPDX-License-Identifier: GPL-3.0-or-later
#include "engine/io/sensors/SensorLog.h"

#include "engine/io/sensors/OscGyroReceiver.h"

#include <fmt/core.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace underfoot::engine {

SensorLogWriter::SensorLogWriter(const std::string& path, double originS)
    : path_(path), originS_(originS) {
    file_ = std::fopen(path.c_str(), "w");
    if (!file_)
        throw std::runtime_error(
            fmt::format("{}: cannot create the sensor log: {}", path, std::strerror(errno)));
    fmt::print(file_, "time_s,kind,device_ms,index,lh,lt,rh,rt,foot,part,strength,"
                      "derivative_per_s,bank_index,gain,start_sample,limb,angular_velocity_dps,"
                      "sequence\n");
}

SensorLogWriter::~SensorLogWriter() {
    if (file_) std::fclose(file_);
}

void SensorLogWriter::write(const ShoeFrame& f) {
    fmt::print(file_, "{:.6f},frame,{},{},{},{},{},{},,,,,,,,,,\n", f.timeS - originS_, f.deviceMs,
               f.index, f.raw[0], f.raw[1], f.raw[2], f.raw[3]);
    ++rows_;
}

void SensorLogWriter::write(const StepEvent& e) {
    fmt::print(file_, "{:.6f},step,{},{},,,,,{},{},{:.4f},{:.1f},,,,,,\n", e.timeS - originS_,
               e.deviceMs, e.frameIndex, footName(e.foot), footPartName(e.part), e.strength,
               e.derivativePerS);
    ++rows_;
}

void SensorLogWriter::write(const StepPlayback& p) {
    const StepEvent& e = p.step;
    fmt::print(file_, "{:.6f},grf,{},{},,,,,{},{},{:.4f},{:.1f},{},{:.4f},{},,,\n",
               e.timeS - originS_, e.deviceMs, e.frameIndex, footName(e.foot), footPartName(e.part),
               e.strength, e.derivativePerS, p.bankIndex, p.gain, p.startSample);
    ++rows_;
}

void SensorLogWriter::write(const GyroSample& s) {
    fmt::print(file_, "{:.6f},gyro,,,,,,,,,,,,,,{},{:.6g},{}\n", s.timeS - originS_,
               limbName(s.limb), s.angularVelocityDps, s.sequence);
    ++rows_;
}

void SensorLogWriter::flush() {
    if (std::fflush(file_) != 0 || std::ferror(file_))
        throw std::runtime_error(
            fmt::format("{}: writing the sensor log failed: {}", path_, std::strerror(errno)));
}

} // namespace underfoot::engine
