// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/LeaseHolder.h"

#include <cerrno>
#include <fstream>
#include <sstream>

#include <signal.h>
#include <unistd.h>

namespace underfoot::experiment {

namespace {

std::string hostNameOfThis() {
    char buf[256] = {};
    if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown-host";
    return buf;
}

/// The state letter and start time of /proc/PID/stat: the command name (field 2) may hold
/// spaces and parentheses, so fields are counted after its last ')'.
struct ProcStat {
    char state = '?';
    std::uint64_t startTicks = 0;
};

std::optional<ProcStat> readProcStat(std::int64_t pid) {
    std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
    if (!in) return std::nullopt;
    std::string line;
    if (!std::getline(in, line)) return std::nullopt;
    const auto close = line.rfind(')');
    if (close == std::string::npos) return std::nullopt;
    std::istringstream rest(line.substr(close + 1));
    ProcStat st;
    rest >> st.state; // field 3
    std::string field;
    for (int f = 4; f < 22 && rest >> field; ++f) {
    }
    if (!(rest >> st.startTicks)) return std::nullopt; // field 22
    return st;
}

} // namespace

const char* toString(HolderState s) {
    switch (s) {
    case HolderState::Self:
        return "this process";
    case HolderState::Live:
        return "live";
    case HolderState::Dead:
        return "dead";
    case HolderState::Reused:
        return "PID reused";
    case HolderState::OtherBoot:
        return "before a reboot";
    case HolderState::OtherHost:
        return "other host";
    }
    return "?";
}

std::optional<std::uint64_t> processStartTicks(std::int64_t pid) {
    if (pid <= 0) return std::nullopt;
    const auto st = readProcStat(pid);
    if (!st) return std::nullopt;
    if (st->state == 'Z' || st->state == 'X') return std::nullopt; // killed, not yet reaped
    return st->startTicks;
}

std::string bootId() {
    std::ifstream in("/proc/sys/kernel/random/boot_id");
    std::string id;
    std::getline(in, id);
    return id;
}

LeaseHolder thisProcess() {
    LeaseHolder h;
    h.pid = ::getpid();
    h.host = hostNameOfThis();
    h.startTicks = processStartTicks(h.pid);
    h.bootId = bootId();
    return h;
}

HolderState classifyHolder(const LeaseHolder& holder, const LeaseHolder& me) {
    if (holder.host != me.host) return HolderState::OtherHost;
    if (!holder.bootId.empty() && !me.bootId.empty() && holder.bootId != me.bootId)
        return HolderState::OtherBoot;
    if (holder.pid == me.pid && (!holder.startTicks || holder.startTicks == me.startTicks))
        return HolderState::Self;
    if (holder.pid <= 0) return HolderState::Dead;
    const auto start = processStartTicks(holder.pid);
    if (!start) {
        // No readable /proc entry: either gone, or /proc is not mounted (then ask the kernel).
        if (readProcStat(me.pid)) return HolderState::Dead;
        return ::kill(static_cast<pid_t>(holder.pid), 0) != 0 && errno == ESRCH ? HolderState::Dead
                                                                                : HolderState::Live;
    }
    if (holder.startTicks && *holder.startTicks != *start) return HolderState::Reused;
    return HolderState::Live;
}

} // namespace underfoot::experiment
