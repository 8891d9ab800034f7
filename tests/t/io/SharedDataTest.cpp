// Every file in ../shared/data, checked against figures computed independently with this
// Python (struct only, no reader of ours), run in ../shared/data:
//   data = open(path, 'rb').read(); end = data.index(b'end_header\n') + 11
//   props = [l.split()[2] for l in header if l.startswith('property')]
//   vals = struct.unpack_from('<%df' % (n * len(props)), data, end)
//   col = lambda name: vals[props.index(name)::len(props)]
//   -> n, number of f_rest props, min/max x, math.fsum(x), min/max opacity,
//      exp(min/max scale_0), min/max f_dc_0, quaternion norm range, trailing bytes
//   .splat: n = len(data) // 32; x = float32 at record offset 0; alpha byte at 27.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "TestUtility.h"
#include "open3d/core/Logging.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using geometry::PointCloud;

struct Expected {
    const char* file;
    int64_t n;
    int degree;
    double min_x, max_x, sum_x;
    double min_scale0, max_scale0;  // linear
    int64_t trailing_bytes;
};

// Figures from the Python above (printed with 6 significant digits).
const Expected kFiles[] = {
    {"playbot/playbot_31k.ply", 31000, 2, -1.0269, 1.02928, -268.000942, 6.99397e-05, 0.296438, 0},
    {"playbot/playbot_125k.ply", 125000, 2, -1.02831, 1.03114, -782.153197, 4.03818e-05, 0.404836,
     0},
    {"biker/biker_152k.ply", 152746, 0, -0.621338, 0.414307, -7419.369629, 4.53999e-05, 0.144064,
     0},
    {"train3/train_3points.ply", 3, 3, -2.74808, 2.00785, -2.239456, 0.00341077, 0.0205153, 0},
    {"sh3_iter7000/point_cloud.ply", 9080, 3, -409.66, 471.384, 447353.613106, 0.00562162, 227.68,
     0},
    {"pc_short/pc_short.ply", 100, 3, -0.932074, 0.0834385, -58.935648, 2.51065e-05, 0.0353115, 0},
    {"pc_short/pc_short_trailing_bytes.ply", 100, 3, -0.932074, 0.0834385, -58.935648, 2.51065e-05,
     0.0353115, 14029},
    {"chair/chair.splat", 89945, 0, -0.253645, 0.253992, 1287.029634, 1.17464e-08, 0.0674766, 0},
    {"train3/one_splat.splat", 1, 0, -21.4309, -21.4309, -21.430897, 1.77184, 1.77184, 0},
    {"sh3_iter7000/model.splat", 22764, 0, -409.637, 498.318, 786410.783085, 0.00562162, 226.459,
     0},
};

// Names the file instead of dumping the struct's bytes in test listings.
void PrintTo(const Expected& e, std::ostream* os) { *os << e.file; }

class SharedData : public ::testing::TestWithParam<Expected> {};

TEST_P(SharedData, MatchesIndependentFigures) {
    const Expected& e = GetParam();
    OPEN3D_REQUIRE_DATA(e.file);
    PointCloud cloud;
    const auto report = ReadPointCloud(tests::DataPath(e.file), cloud);
    ASSERT_EQ(cloud.NumPoints(), e.n);
    ASSERT_TRUE(cloud.IsGaussianSplat());
    EXPECT_EQ(cloud.GaussianSplatGetSHOrder(), e.degree);
    EXPECT_EQ(report.trailing_bytes, e.trailing_bytes);
    EXPECT_EQ(report.dropped_non_finite, 0);

    const float* p = cloud.GetPointPositions().Data<float>();
    double min_x = 1e30, max_x = -1e30, sum_x = 0;
    for (int64_t i = 0; i < e.n; ++i) {
        min_x = std::min(min_x, double(p[i * 3]));
        max_x = std::max(max_x, double(p[i * 3]));
        sum_x += p[i * 3];
    }
    // 6 significant digits printed: relative 1e-5 tolerance.
    EXPECT_NEAR(min_x, e.min_x, 1e-5 * std::abs(e.min_x));
    EXPECT_NEAR(max_x, e.max_x, 1e-5 * std::abs(e.max_x));
    // Plain double summation vs math.fsum, figure printed to 6 decimals: measured 4e-13 relative.
    EXPECT_NEAR(sum_x, e.sum_x, 1e-6 * std::max(1.0, std::abs(e.sum_x)));

    const float* s = cloud.GetPointAttr("scale").Data<float>();
    double min_s = 1e30, max_s = 0;
    for (int64_t i = 0; i < e.n; ++i) {
        min_s = std::min(min_s, double(s[i * 3]));
        max_s = std::max(max_s, double(s[i * 3]));
    }
    EXPECT_NEAR(min_s, e.min_scale0, 1e-5 * e.min_scale0);
    EXPECT_NEAR(max_s, e.max_scale0, 1e-5 * e.max_scale0);

    // Every quaternion unit length after reading (sh3_iter7000 stores norms 0.62-1.15).
    const float* q = cloud.GetPointAttr("rot").Data<float>();
    for (int64_t i = 0; i < e.n; ++i) {
        const double norm =
            std::sqrt(double(q[i * 4]) * q[i * 4] + double(q[i * 4 + 1]) * q[i * 4 + 1] +
                      double(q[i * 4 + 2]) * q[i * 4 + 2] + double(q[i * 4 + 3]) * q[i * 4 + 3]);
        ASSERT_NEAR(norm, 1.0, 1e-6) << e.file << " splat " << i;  // float rounding: <= 2.4e-7
    }
    // Opacity is a finite logit; .splat alpha 0 (chair) maps to logit(1e-6) ~ -13.8.
    const float* o = cloud.GetPointAttr("opacity").Data<float>();
    for (int64_t i = 0; i < e.n; ++i) ASSERT_TRUE(std::isfinite(o[i]));
}

INSTANTIATE_TEST_SUITE_P(AllFiles, SharedData, ::testing::ValuesIn(kFiles),
                         [](const ::testing::TestParamInfo<Expected>& info) {
                             std::string name = info.param.file;
                             for (char& c : name) {
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             }
                             return name;
                         });

TEST(SharedData, PlyRoundTripOfRealFilesIsExact) {
    for (const char* file : {"playbot/playbot_31k.ply", "sh3_iter7000/point_cloud.ply"}) {
        if (!tests::FileExists(tests::DataPath(file))) {
            OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE(tests::DataPath(file) + " absent");
        }
        PointCloud original, back;
        ReadPointCloud(tests::DataPath(file), original);
        const std::string path = tests::TempDir() + "/copy.ply";
        WritePointCloud(path, original);
        ReadPointCloud(path, back);
        EXPECT_TRUE(back == original) << file;
    }
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
