// The SOG writer's 256-entry scale codebook keeps a scene's largest splats their size: a
// plain k-means over the log-scales spends its entries where the splats are many (the small
// ones) and rounded chair.splat's largest splats down by 0.53 in log-scale (41% smaller).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "TestUtility.h"
#include "open3d/t/io/Codebook.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace tests {
namespace {

TEST(SogScaleCodebook, LargestSplatsKeepTheirSize) {
    OPEN3D_REQUIRE_DATA("chair/chair.splat");
    t::geometry::PointCloud original, back;
    t::io::ReadPointCloud(DataPath("chair/chair.splat"), original);
    const std::string sog = TempDir() + "/chair.sog";
    t::io::WritePointCloud(sog, original);
    t::io::ReadPointCloud(sog, back);
    ASSERT_EQ(back.NumPoints(), original.NumPoints());
    const float* a = original.GetPointAttr("scale").Data<float>();
    const float* b = back.GetPointAttr("scale").Data<float>();
    const int64_t n = original.NumPoints() * 3;
    // The 1% largest scale values and their log error after the round trip.
    std::vector<int64_t> order(n);
    std::iota(order.begin(), order.end(), 0);
    const int64_t top = n / 100;
    std::partial_sort(order.begin(), order.begin() + top, order.end(),
                      [&](int64_t x, int64_t y) { return a[x] > a[y]; });
    double worst = 0.0, sum = 0.0;
    for (int64_t k = 0; k < top; ++k) {
        const double e = std::abs(std::log(double(b[order[k]])) - std::log(double(a[order[k]])));
        worst = std::max(worst, e);
        sum += e;
    }
    std::printf("chair.sog: largest 1%% of scales, log error max %.4f, mean %.4f\n", worst,
                sum / double(top));
    // Measured: max 0.197, mean 0.010 (the plain k-means: max 0.531, mean 0.046).
    EXPECT_LT(worst, 0.3);
    EXPECT_LT(sum / double(top), 0.03);
}

TEST(SogScaleCodebook, WeightsPullEntriesToHeavyValues) {
    // 10,000 distinct values evenly in [0, 1) of weight 1 and 100 in [1, 2) of weight 1000:
    // unweighted, 1% of the values get about 1% of the entries (spacing ~0.4); weighted, the
    // heavy ones hold most of the weight and get most of the entries.
    std::vector<float> values, weights;
    for (int i = 0; i < 10000; ++i) values.push_back(float(i) / 10000.0f), weights.push_back(1);
    for (int i = 0; i < 100; ++i)
        values.push_back(1.0f + float(i) / 100.0f), weights.push_back(1000);
    const auto worst_heavy = [&](const std::vector<float>& codebook,
                                 const std::vector<uint8_t>& labels) {
        double worst = 0.0;
        for (size_t i = 10000; i < values.size(); ++i) {
            worst = std::max(worst, std::abs(double(codebook[labels[i]]) - values[i]));
        }
        return worst;
    };
    std::vector<uint8_t> plain_labels, weighted_labels;
    const auto plain = t::io::Quantise1D(values, plain_labels);
    const auto weighted = t::io::Quantise1D(values, weighted_labels, weights);
    EXPECT_GT(worst_heavy(plain, plain_labels), 0.02);
    EXPECT_LT(worst_heavy(weighted, weighted_labels), 0.005);  // ~200 entries over 100 values
    EXPECT_TRUE(std::is_sorted(weighted.begin(), weighted.end()));
}

}  // namespace
}  // namespace tests
}  // namespace open3d
