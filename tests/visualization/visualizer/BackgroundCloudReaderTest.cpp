// The viewer's background file reads: the same cloud as a read on the calling thread, the
// reader's errors at TakeResult, one read at a time.
#include "open3d/visualization/visualizer/BackgroundCloudReader.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <thread>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace tests {
namespace {

using visualization::BackgroundCloudReader;

// Polls as the viewer's loop does, ten times a second, for up to a minute.
std::optional<t::geometry::PointCloud> WaitForResult(BackgroundCloudReader& reader) {
    for (int i = 0; i < 600; ++i) {
        if (std::optional<t::geometry::PointCloud> cloud = reader.TakeResult()) return cloud;
        if (!reader.IsBusy()) return std::nullopt;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return std::nullopt;
}

TEST(BackgroundCloudReader, ReadsWhatTheCallingThreadReads) {
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    const std::string path = DataPath("playbot/playbot_31k.ply");
    BackgroundCloudReader reader;
    EXPECT_FALSE(reader.IsBusy());
    EXPECT_FALSE(reader.TakeResult().has_value());
    reader.Start(path);
    EXPECT_TRUE(reader.IsBusy());
    EXPECT_NE(reader.Describe().find("Loading playbot_31k.ply ("), std::string::npos)
        << reader.Describe();
    EXPECT_THROW(reader.Start(path), core::Open3DError);  // one read at a time
    const std::optional<t::geometry::PointCloud> cloud = WaitForResult(reader);
    ASSERT_TRUE(cloud.has_value());
    EXPECT_FALSE(reader.IsBusy());
    EXPECT_TRUE(reader.Describe().empty());
    t::geometry::PointCloud expected;
    t::io::ReadPointCloud(path, expected);
    ASSERT_EQ(cloud->NumPoints(), expected.NumPoints());
    for (const char* name : {"positions", "scale", "rot", "opacity", "f_dc", "f_rest"}) {
        const core::Tensor& a = cloud->GetPointAttr(name);
        const core::Tensor& b = expected.GetPointAttr(name);
        ASSERT_EQ(a.NumElements(), b.NumElements()) << name;
        EXPECT_EQ(std::memcmp(a.RawData(), b.RawData(), a.NumBytes()), 0) << name;
    }
}

TEST(BackgroundCloudReader, ErrorsArriveAtTakeResult) {
    const std::string dir = TempDir();
    BackgroundCloudReader reader;
    reader.Start(dir + "/missing.ply");
    std::string message;
    for (int i = 0; i < 6000 && reader.IsBusy(); ++i) {  // a minute: only a hang
        try {
            reader.TakeResult();
        } catch (const core::Open3DError& e) {
            message = e.what();
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    EXPECT_NE(message.find("missing.ply"), std::string::npos) << message;
    EXPECT_FALSE(reader.IsBusy());
    // Free again after the error; an xyz-only PLY is refused for its missing attributes.
    const std::string xyz = dir + "/xyz.ply";
    std::ofstream(xyz) << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                          "property float y\nproperty float z\nend_header\n0 0 0\n";
    reader.Start(xyz);
    try {
        WaitForResult(reader);
        ADD_FAILURE() << "an xyz-only PLY was accepted";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("xyz.ply"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace tests
}  // namespace open3d
