// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Who holds a participant's session lease, and whether that holder can still write: a process
/// is named by host, boot id (/proc/sys/kernel/random/boot_id), PID and its start time in clock
/// ticks since boot (field 22 of /proc/PID/stat, proc(5)). A PID alone is not enough: after a
/// reboot or in a re-created container the same PID is another process, and a killed process
/// that its parent has not reaped yet (a zombie) still answers kill(pid, 0).
#include <cstdint>
#include <optional>
#include <string>

namespace underfoot::experiment {

struct LeaseHolder {
    std::int64_t pid = 0;
    std::string host;
    /// Start time in clock ticks since boot; nullopt for leases written before it was stored.
    std::optional<std::uint64_t> startTicks;
    /// The kernel's boot id; empty when unknown.
    std::string bootId;
};

/// What became of a lease's holder, seen from this process.
enum class HolderState {
    Self,      ///< this very process (an earlier store of it)
    Live,      ///< a live process on this host and boot: it may still write
    Dead,      ///< no such process on this host (or a zombie: killed, not yet reaped)
    Reused,    ///< the PID now names another process (different start time)
    OtherBoot, ///< written before this host's last reboot: certainly gone
    OtherHost, ///< another host name (another machine or a re-created container)
};

const char* toString(HolderState s);

/// This process as a lease holder.
LeaseHolder thisProcess();

/// The start time (clock ticks since boot) of process `pid` on this host; nullopt when there is
/// no such process, it is a zombie, or /proc cannot be read.
std::optional<std::uint64_t> processStartTicks(std::int64_t pid);

/// The kernel's boot id ("" when unreadable).
std::string bootId();

/// What became of `holder`, seen from `me` (probing /proc for holders on this host and boot).
HolderState classifyHolder(const LeaseHolder& holder, const LeaseHolder& me);

} // namespace underfoot::experiment
