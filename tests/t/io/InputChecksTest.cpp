// Inputs that used to hang or hide the reason: a FIFO given as a file, a PLY header that
// never ends, a .splat with negative scales, a plain xyz PLY handed to a renderer.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdint>
#include <cstring>
#include <fstream>

#include "PlyTestFiles.h"
#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/io/ImageIO.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using geometry::PointCloud;

// The message of what `read` throws ("" when it does not throw).
template <typename F>
std::string ErrorOf(F read) {
    try {
        read();
    } catch (const core::Open3DError& e) {
        return e.what();
    }
    return "";
}

TEST(InputChecks, FifoIsRefusedInsteadOfBlocking) {
    // open() of a FIFO without a writer blocks forever: with the bug this test hangs
    // until ctest's timeout.
    const std::string fifo = tests::TempDir() + "/pipe.ply";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
    PointCloud cloud;
    for (const std::string& message :
         {ErrorOf([&] { ReadPointCloud(fifo, cloud); }), ErrorOf([&] { ReadPNG(fifo); }),
          ErrorOf([&] { ReadNpy(fifo); })}) {
        EXPECT_NE(message.find(fifo), std::string::npos) << message;
        EXPECT_NE(message.find("not a regular file"), std::string::npos) << message;
    }
}

TEST(InputChecks, PlyWithoutEndHeaderSaysTheHeaderIsIncomplete) {
    const std::string path = tests::TempDir() + "/no_end.ply";
    std::string bytes = "ply\nformat binary_little_endian 1.0\nelement vertex 1000\n";
    for (int i = 0; i < 4000; ++i) bytes += static_cast<char>((i * 37) & 0xff);  // binary rows
    tests::WriteText(path, bytes);
    PointCloud cloud;
    const std::string message = ErrorOf([&] { ReadPointCloud(path, cloud); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find("incomplete"), std::string::npos) << message;
    EXPECT_NE(message.find("no 'end_header' line in all of its"), std::string::npos) << message;
    for (const unsigned char c : message) {
        EXPECT_TRUE(c >= 0x20 && c < 0x7f) << "binary byte " << int(c) << " in: " << message;
    }
}

TEST(InputChecks, BinaryInAHeaderLineIsShownEscaped) {
    const std::string path = tests::TempDir() + "/binary_line.ply";
    tests::WriteText(path, std::string("ply\nformat ascii 1.0\n\x01\x02garbage\xff\nend_header\n"));
    PointCloud cloud;
    const std::string message = ErrorOf([&] { ReadPointCloud(path, cloud); });
    EXPECT_NE(message.find("line 3"), std::string::npos) << message;
    EXPECT_NE(message.find("\\x01\\x02garbage\\xff"), std::string::npos) << message;
}

TEST(InputChecks, SplatWithANegativeScaleIsRefusedWithItsIndex) {
    const std::string path = tests::TempDir() + "/negative.splat";
    std::string bytes(3 * 32, '\0');
    for (int i = 0; i < 3; ++i) {
        const float scale[3] = {0.1f, i == 2 ? -0.5f : 0.2f, 0.3f};
        std::memcpy(&bytes[i * 32 + 12], scale, sizeof(scale));
        bytes[i * 32 + 28] = static_cast<char>(255);  // rotation w
    }
    tests::WriteText(path, bytes);
    PointCloud cloud;
    const std::string message = ErrorOf([&] { ReadPointCloud(path, cloud); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find("splat 2 has a negative scale -0.5"), std::string::npos) << message;
}

TEST(InputChecks, PositionsOnlyPlyIsNamedAsNotASplatScene) {
    const std::string path = tests::TempDir() + "/xyz.ply";
    tests::WriteFloatPly(path, {"x", "y", "z"}, {1, 2, 3, 4, 5, 6});
    PointCloud cloud;
    ReadPointCloud(path, cloud);  // a plain point cloud reads fine
    const std::string message = ErrorOf([&] { RequireGaussianSplat(path, cloud); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find("no Gaussian splat attributes"), std::string::npos) << message;
    EXPECT_NE(message.find("positions only"), std::string::npos) << message;
    EXPECT_NE(message.find("scale, rot, opacity, f_dc are missing"), std::string::npos) << message;
    tests::WriteFloatPly(path, tests::GaussianPropertyNames(0), tests::PlausibleRows(0, 2));
    ReadPointCloud(path, cloud);
    EXPECT_NO_THROW(RequireGaussianSplat(path, cloud));
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
