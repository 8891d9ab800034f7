// Selecting splats by a screen region (cpu/ViewSelection.h): the centre must project inside the
// region, and by default the splat must show there (a blend weight of at least 1/255 under the
// reference's rules), so what a near opaque splat hides, and what is too faint to draw, is left
// out unless asked for. Scenes built by hand with the values worked out in the comments.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "SplatTestScene.h"
#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/ViewSelection.h"

namespace open3d {
namespace tests {
namespace {

namespace cpu = visualization::rendering::cpu;
using visualization::rendering::RenderConfig;

TEST(ViewSelection, HiddenAndFaintSplatsAreLeftOutUnlessAskedFor) {
    // Camera at the origin looking along +z, fx = 100, the axis on pixel (32, 32); region
    // [29, 35]^2.
    // 0: A at z = 5, scale 2 (sigma 40 px), opacity 0.99995: alpha = 0.99 (the cap) on every
    //    pixel of the region (3 px from its centre: 0.99995 exp(-0.0028) > 0.99).
    // 1: B behind A at z = 6, opacity 0.3: after A, T = 0.01, so B adds at most 0.3 x 0.01 =
    //    0.003 < 1/255 to any pixel of the region (alone it would show with 0.3).
    // 2: D in front at z = 4 with opacity 0.002 < 1/255: never blended.
    // 3: C in front at z = 4.5, x = 0.2: its centre projects to x = 36.4, outside the region,
    //    though its footprint (sigma 6.7 px) covers part of it.
    std::vector<TestSplat> splats(4);
    splats[0].position = {0, 0, 5};
    splats[0].scale = {2, 2, 2};
    splats[0].opacity = 0.99995;
    splats[1].position = {0, 0, 6};
    splats[1].scale = {0.2, 0.2, 0.2};
    splats[1].opacity = 0.3;
    splats[2].position = {0, 0, 4};
    splats[2].scale = {0.3, 0.3, 0.3};
    splats[2].opacity = 0.002;
    splats[3].position = {0.2, 0, 4.5};
    splats[3].scale = {0.3, 0.3, 0.3};
    splats[3].opacity = 0.5;
    const t::geometry::PointCloud cloud = MakeCloud(splats);
    const std::vector<Eigen::Vector2d> region = cpu::RectanglePolygon(29, 29, 35, 35);
    const RenderConfig config;
    EXPECT_EQ(cpu::SelectSplatsInView(cloud, MakeTestCamera(), config, region),
              (std::vector<int64_t>{0}));
    EXPECT_EQ(cpu::SelectSplatsInView(cloud, MakeTestCamera(), config, region, true),
              (std::vector<int64_t>{0, 1, 2}));
    // A region around C's centre takes C only: A shows there too (through C's 0.5), but its
    // centre (32, 32) is outside.
    EXPECT_EQ(cpu::SelectSplatsInView(cloud, MakeTestCamera(), config,
                                      cpu::RectanglePolygon(33, 28, 40, 36)),
              (std::vector<int64_t>{3}));
}

TEST(ViewSelection, ALassoTakesTheCentresInsideIt) {
    // 400 small splats on the plane z = 5; a triangle lasso. With include_occluded the result
    // is every splat whose centre (100 X / 5 + 32, 100 Y / 5 + 32, from the stored float
    // positions) lies inside the triangle by barycentric signs, computed here; by default a
    // subset (a splat can hide another at the same pixel), at least 90% of it here.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.5, 1.5);
    std::vector<TestSplat> splats(400);
    for (TestSplat& s : splats) {
        s.position = {u(rng), u(rng), 5.0};
        s.scale = {0.01, 0.01, 0.01};
        s.opacity = 0.9;
    }
    const t::geometry::PointCloud cloud = MakeCloud(splats);
    const Eigen::Vector2d a(5, 5), b(60, 10), c(20, 60);
    const auto side = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q,
                         const Eigen::Vector2d& r) {
        return (q.x() - p.x()) * (r.y() - p.y()) - (q.y() - p.y()) * (r.x() - p.x());
    };
    std::vector<int64_t> want;
    const float* pos = cloud.GetPointPositions().Data<float>();
    for (int64_t i = 0; i < 400; ++i) {
        const Eigen::Vector2d p(100.0 * pos[3 * i] / pos[3 * i + 2] + 32.0,
                                100.0 * pos[3 * i + 1] / pos[3 * i + 2] + 32.0);
        const double s1 = side(a, b, p), s2 = side(b, c, p), s3 = side(c, a, p);
        if ((s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0)) want.push_back(i);
    }
    ASSERT_GT(want.size(), 50u);
    const RenderConfig config;
    EXPECT_EQ(cpu::SelectSplatsInView(cloud, MakeTestCamera(), config, {a, b, c}, true), want);
    const std::vector<int64_t> shown =
        cpu::SelectSplatsInView(cloud, MakeTestCamera(), config, {a, b, c});
    EXPECT_TRUE(std::includes(want.begin(), want.end(), shown.begin(), shown.end()));
    EXPECT_GE(shown.size(), want.size() * 9 / 10);
}

TEST(ViewSelection, PolygonsAreClosedAndCheckedFirst) {
    const std::vector<Eigen::Vector2d> square = cpu::RectanglePolygon(4, 4, 0, 0);  // any order
    EXPECT_TRUE(cpu::PolygonContains(square, {0, 0}));                              // a corner
    EXPECT_TRUE(cpu::PolygonContains(square, {4, 2}));                              // an edge
    EXPECT_TRUE(cpu::PolygonContains(square, {2, 2}));
    EXPECT_FALSE(cpu::PolygonContains(square, {4.001, 2}));
    const t::geometry::PointCloud cloud = MakeCloud({TestSplat()});
    EXPECT_THROW(cpu::SelectSplatsInView(cloud, MakeTestCamera(), RenderConfig(), {{0, 0}, {1, 1}}),
                 core::Open3DError);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
