// Readers refuse a scene that does not fit in host memory before they allocate it, naming
// the file, the bytes and how many splats would fit (OPEN3D_HOST_MEMORY_LIMIT stands in
// for a small machine).
#include <gtest/gtest.h>

#include <string>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace tests {
namespace {

TEST(ReaderMemoryCheck, RefusesWithTheNumbers) {
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    const std::string path = DataPath("playbot/playbot_31k.ply");
    // SH degree 2: 3 + 3 + 4 + 1 + 3 + 24 = 38 floats, 152 bytes a splat; 31000 splats
    // need 4712000 bytes; 1 MB holds 6578 of them, 17857 of degree 0 (56 bytes).
    ScopedEnvironment limit("OPEN3D_HOST_MEMORY_LIMIT", "1000000");
    t::geometry::PointCloud cloud;
    try {
        t::io::ReadPointCloud(path, cloud);
        FAIL() << "read 4.7 MB with 1 MB available";
    } catch (const core::Open3DError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "'" + path +
                      "': 31000 splats of SH degree 2 needs 4.7 MB of memory, 1.0 MB is "
                      "available (OPEN3D_HOST_MEMORY_LIMIT); at most 6578 splats of this "
                      "degree fit (17857 of SH degree 0)");
    }
    EXPECT_EQ(cloud.NumPoints(), 0);
}

TEST(ReaderMemoryCheck, LimitsTakeTheSizesOfEveryFlag) {
    // The variables take what --gpu-budget takes (1G was "not a number of bytes", and the
    // Vulkan device was then given up silently).
    {
        ScopedEnvironment limit("OPEN3D_HOST_MEMORY_LIMIT", "1G");
        EXPECT_EQ(core::ReadByteCountVariable("OPEN3D_HOST_MEMORY_LIMIT"), uint64_t(1) << 30);
        EXPECT_LE(core::AvailableHostMemory(), uint64_t(1) << 30);
    }
    ScopedEnvironment bad("OPEN3D_DEVICE_MEMORY_LIMIT", "1Gjunk");
    try {
        core::ReadByteCountVariable("OPEN3D_DEVICE_MEMORY_LIMIT");
        ADD_FAILURE() << "accepted";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("OPEN3D_DEVICE_MEMORY_LIMIT: '1Gjunk' is not a size"),
                  std::string::npos)
            << e.what();
    }
}

TEST(ReaderMemoryCheck, ReadsWhatFits) {
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    ScopedEnvironment limit("OPEN3D_HOST_MEMORY_LIMIT", "4712000");  // exactly the columns
    t::geometry::PointCloud cloud;
    t::io::ReadPointCloud(DataPath("playbot/playbot_31k.ply"), cloud);
    EXPECT_EQ(cloud.NumPoints(), 31000);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
