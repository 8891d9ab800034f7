// core::InstallCrashReport: a crash prints the signal and a call stack to stderr, then ends the
// process by the same signal (gtest death tests run the statement in a child process).
#include <gtest/gtest.h>

#include <csignal>

#include "open3d/core/CrashReport.h"

namespace open3d {
namespace tests {
namespace {

[[gnu::noinline]] void CrashHere(int signal_number) { std::raise(signal_number); }

TEST(CrashReportDeathTest, ACrashPrintsTheSignalAndTheStackAndEndsBySignal) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    for (int s : {SIGSEGV, SIGABRT}) {
        EXPECT_EXIT(
            {
                core::InstallCrashReport();
                core::InstallCrashReport();  // a second call changes nothing
                CrashHere(s);
            },
            ::testing::KilledBySignal(s),
            "open3d: fatal signal .*call stack .*innermost first:\n.*tests_core");
    }
}

}  // namespace
}  // namespace tests
}  // namespace open3d
