// Writing SH to a compressed PLY loses precision the rest of the format does not (8 bits
// over [-4, 4]); the writer says so with this cloud's numbers, and a clamped coefficient
// is counted rather than lost silently.
#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <vector>

#include "RandomSplatCloud.h"
#include "TestUtility.h"
#include "open3d/core/Logging.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {
namespace {

std::vector<std::string> WarningsOfWriting(const std::string& path,
                                           const geometry::PointCloud& cloud) {
    return tests::CaptureWarnings([&] { WritePointCloud(path, cloud); });
}

TEST(CompressedPlySh, WritingShWarnsWithTheCloudsErrorAndClampedCount) {
    geometry::PointCloud cloud = RandomCloud(300, 1, 7);
    float* rest = cloud.GetPointAttr("f_rest").Data<float>();
    for (int k = 0; k < 9 * 300; ++k) rest[k] *= 0.1f;  // well inside [-4, 4]
    rest[5] = 6.0f;                                     // one coefficient past the range
    const std::string path = tests::TempDir() + "/sh.compressed.ply";
    const std::vector<std::string> warnings = WarningsOfWriting(path, cloud);
    ASSERT_EQ(warnings.size(), 1u);
    // The clamped coefficient's error is 6 - 4 = 2 (the largest); 1 of 300 * 9 is clamped.
    EXPECT_NE(warnings[0].find("'" + path + "': compressed PLY keeps SH (f_rest) in 8 bits"),
              std::string::npos)
        << warnings[0];
    EXPECT_NE(warnings[0].find("errors up to 2.0000"), std::string::npos) << warnings[0];
    EXPECT_NE(warnings[0].find("1 of 2700 coefficients clamped"), std::string::npos) << warnings[0];
}

TEST(CompressedPlySh, NoShNoWarning) {
    const std::string path = tests::TempDir() + "/sh0.compressed.ply";
    EXPECT_TRUE(WarningsOfWriting(path, RandomCloud(300, 0, 7)).empty());
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
