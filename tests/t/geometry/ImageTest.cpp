#include <gtest/gtest.h>

#include <cmath>

#include "open3d/core/Exception.h"
#include "open3d/t/geometry/Image.h"
#include "open3d/t/geometry/ImageMetrics.h"

namespace open3d {
namespace tests {

using t::geometry::Image;

TEST(Image, ShapeAccessAndConversions) {
    Image img(2, 3, 4, core::Dtype::Float32);
    EXPECT_EQ(img.GetRows(), 2);
    EXPECT_EQ(img.GetCols(), 3);
    EXPECT_EQ(img.GetChannels(), 4);
    img.At<float>(1, 2, 3) = 0.5f;
    EXPECT_EQ(img.Data<float>()[(1 * 3 + 2) * 4 + 3], 0.5f);
    img.At<float>(0, 0, 0) = 2.0f;                   // clamps to 255
    img.At<float>(0, 0, 1) = -1.0f;                  // clamps to 0
    img.At<float>(0, 0, 2) = 0.5f / 255.0f + 1e-6f;  // rounds up to 1
    const Image u8 = img.ToUInt8();
    EXPECT_EQ(u8.At<uint8_t>(0, 0, 0), 255);
    EXPECT_EQ(u8.At<uint8_t>(0, 0, 1), 0);
    EXPECT_EQ(u8.At<uint8_t>(0, 0, 2), 1);
    EXPECT_EQ(u8.At<uint8_t>(1, 2, 3), 128);  // 127.5 rounds half away from zero
    const Image alpha = img.SelectChannels(3, 1);
    EXPECT_EQ(alpha.GetChannels(), 1);
    EXPECT_EQ(alpha.At<float>(1, 2), 0.5f);
    EXPECT_THROW(img.SelectChannels(3, 2), core::Open3DError);
    EXPECT_THROW(Image(2, 2, 5, core::Dtype::UInt8), core::Open3DError);
    EXPECT_EQ(u8.ToFloat(1.0 / 255).At<float>(0, 0, 0), 1.0f);
}

TEST(Image, BoxDownsampleAveragesBlocks) {
    // 4 x 6 pixels, 2 channels: value = 10 y + x (+ 100 in channel 1).
    Image img(4, 6, 2, core::Dtype::Float32);
    for (int64_t y = 0; y < 4; ++y) {
        for (int64_t x = 0; x < 6; ++x) {
            img.At<float>(y, x, 0) = float(10 * y + x);
            img.At<float>(y, x, 1) = float(100 + 10 * y + x);
        }
    }
    const Image half = img.BoxDownsample(2);
    ASSERT_EQ(half.GetRows(), 2);
    ASSERT_EQ(half.GetCols(), 3);
    ASSERT_EQ(half.GetChannels(), 2);
    // Block (bx, by) holds 10 (2 by + {0, 1}) + 2 bx + {0, 1}: mean 20 by + 2 bx + 5.5.
    for (int64_t by = 0; by < 2; ++by) {
        for (int64_t bx = 0; bx < 3; ++bx) {
            EXPECT_EQ(half.At<float>(by, bx, 0), float(20 * by + 2 * bx + 5.5));
            EXPECT_EQ(half.At<float>(by, bx, 1), float(100 + 20 * by + 2 * bx + 5.5));
        }
    }
    EXPECT_EQ(img.BoxDownsample(1), img);
    EXPECT_THROW(img.BoxDownsample(4), core::Open3DError);  // 6 columns
    EXPECT_THROW(img.BoxDownsample(0), core::Open3DError);
    EXPECT_THROW(img.ToUInt8().BoxDownsample(2), core::Open3DError);
}

TEST(ImageMetrics, KnownValues) {
    Image a(4, 5, 1, core::Dtype::Float32), b(4, 5, 1, core::Dtype::Float32);
    for (int64_t i = 0; i < 20; ++i) b.Data<float>()[i] = 0.1f;
    b.At<float>(0, 0) = 0.5f;
    // MSE = (19 * 0.01 + 0.25) / 20 = 0.022 (float 0.1 is 0.1 + 1.5e-9).
    const auto m = t::geometry::ComputeImageErrorMetrics(a, b, 1.0, 0.2);
    EXPECT_NEAR(m.psnr_db, 10 * std::log10(1.0 / 0.022), 1e-6);
    EXPECT_NEAR(m.max_abs_error, 0.5, 1e-7);
    EXPECT_NEAR(m.mean_abs_error, (19 * 0.1 + 0.5) / 20, 1e-7);
    EXPECT_NEAR(m.fraction_over_threshold, 1.0 / 20, 1e-12);
    EXPECT_TRUE(std::isinf(t::geometry::ComputePSNR(a, a, 1.0)));
    EXPECT_NEAR(t::geometry::ComputeAbsDifference(a, b).At<float>(0, 0), 0.5f, 0);
    Image c(4, 4, 1, core::Dtype::Float32);
    EXPECT_THROW(t::geometry::ComputePSNR(a, c, 1.0), core::Open3DError);
}

}  // namespace tests
}  // namespace open3d

namespace open3d {
namespace t {
namespace geometry {

TEST(ImageMetrics, AbsErrorPercentileIsNearestRank) {
    // |a - b| = 1, 2, ..., 1000 (shuffled order): the 99.9th percentile by nearest rank is
    // element ceil(0.999 * 1000) - 1 = 998 of the sorted values, i.e. 999.
    Image a(10, 100, 1, core::Dtype::Float32), b(10, 100, 1, core::Dtype::Float32);
    for (int i = 0; i < 1000; ++i) {
        a.Data<float>()[i] = static_cast<float>((i * 7919) % 1000 + 1);
        b.Data<float>()[i] = 0.0f;
    }
    EXPECT_EQ(ComputeAbsErrorPercentile(a, b, 0.999), 999.0);
    EXPECT_EQ(ComputeAbsErrorPercentile(a, b, 1.0), 1000.0);
    EXPECT_EQ(ComputeAbsErrorPercentile(a, b, 0.5), 500.0);
    EXPECT_THROW(ComputeAbsErrorPercentile(a, b, 0.0), core::Open3DError);
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
