// SPDX-License-Identifier: GPL-3.0-or-later
// Lease holders classified from /proc: this process, a live child, a killed child before and
// after it is reaped, a reused PID (another start time), an earlier boot, another host.
#include "experiment/LeaseHolder.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

namespace underfoot::experiment {
namespace {

pid_t idleChild() {
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::pause();
        ::_exit(0);
    }
    return pid;
}

TEST(LeaseHolder, ThisProcessHasAStartTimeAndABootId) {
    const LeaseHolder me = thisProcess();
    ASSERT_TRUE(me.startTicks.has_value());
    EXPECT_EQ(me.bootId.size(), 36u); // a UUID
    EXPECT_EQ(classifyHolder(me, me), HolderState::Self);
}

TEST(LeaseHolder, LiveZombieAndReapedChildren) {
    const LeaseHolder me = thisProcess();
    const pid_t child = idleChild();
    ASSERT_GT(child, 0);
    LeaseHolder h = me;
    h.pid = child;
    h.startTicks = processStartTicks(child);
    ASSERT_TRUE(h.startTicks.has_value());
    EXPECT_EQ(classifyHolder(h, me), HolderState::Live);
    LeaseHolder reused = h;
    *reused.startTicks += 1; // the same PID, started at another time: another process
    EXPECT_EQ(classifyHolder(reused, me), HolderState::Reused);
    LeaseHolder legacy = h; // written before start times were stored
    legacy.startTicks.reset();
    EXPECT_EQ(classifyHolder(legacy, me), HolderState::Live);
    ::kill(child, SIGKILL);
    std::this_thread::sleep_for(std::chrono::milliseconds(100)); // a zombie until reaped
    EXPECT_EQ(classifyHolder(h, me), HolderState::Dead);
    EXPECT_EQ(classifyHolder(legacy, me), HolderState::Dead);
    ::waitpid(child, nullptr, 0);
    EXPECT_EQ(classifyHolder(h, me), HolderState::Dead);
}

TEST(LeaseHolder, EarlierBootAndOtherHost) {
    const LeaseHolder me = thisProcess();
    LeaseHolder h = me; // even a live PID
    h.bootId = "00000000-0000-0000-0000-000000000000";
    EXPECT_EQ(classifyHolder(h, me), HolderState::OtherBoot);
    h = me;
    h.host = "another-container";
    EXPECT_EQ(classifyHolder(h, me), HolderState::OtherHost);
}

} // namespace
} // namespace underfoot::experiment
