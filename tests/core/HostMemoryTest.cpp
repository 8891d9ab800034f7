// The host memory check: what is available (against /proc/meminfo read here), the
// OPEN3D_HOST_MEMORY_LIMIT cap, and the refusal message with its numbers.
#include "open3d/core/HostMemory.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "TestUtility.h"
#include "open3d/core/Exception.h"

namespace open3d {
namespace tests {
namespace {

uint64_t MemTotalBytes() {
    std::ifstream in("/proc/meminfo");
    std::string key, unit;
    uint64_t kb = 0;
    while (in >> key >> kb >> unit) {
        if (key == "MemTotal:") return kb * 1024;
    }
    return 0;
}

TEST(HostMemory, AvailableIsPositiveAndBelowTheTotal) {
    const uint64_t total = MemTotalBytes();
    ASSERT_GT(total, 0u) << "no /proc/meminfo";
    const uint64_t available = core::AvailableHostMemory();
    EXPECT_GT(available, 0u);
    EXPECT_LE(available, total);
}

TEST(HostMemory, TheLimitVariableCapsIt) {
    ScopedEnvironment limit("OPEN3D_HOST_MEMORY_LIMIT", "1500000");
    EXPECT_EQ(core::AvailableHostMemory(), 1500000u);
    EXPECT_NO_THROW(core::RequireHostMemory(1500000, "exactly what is there"));
    try {
        core::RequireHostMemory(2500000, "'x.ply': 9 splats", "at most 5 splats fit");
        FAIL() << "no refusal";
    } catch (const core::Open3DError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "'x.ply': 9 splats needs 2.5 MB of memory, 1.5 MB is available "
                  "(OPEN3D_HOST_MEMORY_LIMIT); at most 5 splats fit");
    }
}

TEST(HostMemory, ABadLimitIsAnError) {
    // "2G" is a size like every flag's (core::ParseByteCount); trailing junk, nothing or a
    // non-finite number is an error.
    for (const char* bad : {"2Gjunk", "G", "inf", "0"}) {
        ScopedEnvironment limit("OPEN3D_HOST_MEMORY_LIMIT", bad);
        EXPECT_THROW(core::AvailableHostMemory(), core::Open3DError) << bad;
    }
    ScopedEnvironment limit("OPEN3D_HOST_MEMORY_LIMIT", "2G");
    EXPECT_LE(core::AvailableHostMemory(), uint64_t(2) << 30);
}

TEST(HostMemory, FormatBytes) {
    EXPECT_EQ(core::FormatBytes(999), "999 bytes");
    EXPECT_EQ(core::FormatBytes(1500), "1.5 kB");
    EXPECT_EQ(core::FormatBytes(23400000), "23.4 MB");
    EXPECT_EQ(core::FormatBytes(5600000000ull), "5.60 GB");
}

}  // namespace
}  // namespace tests
}  // namespace open3d
