// The level-of-detail hierarchy: merged Gaussians against moments computed by hand, the tree's
// structure, and cuts (a partition of the leaves within the budget; a budget of every leaf
// gives the source cloud back bit for bit, so any renderer draws the exact image).
#include <gtest/gtest.h>

#include "RandomGeometry.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/Progress.h"
#include "open3d/t/geometry/SplatHierarchy.h"

namespace open3d {
namespace t {
namespace geometry {
namespace {

using core::Dtype;
using core::Tensor;

struct Splat {
    Eigen::Vector3f position;
    Eigen::Vector3f scale;
    Eigen::Quaternionf rot = Eigen::Quaternionf::Identity();
    float alpha = 0.5f;
    Eigen::Vector3f dc = Eigen::Vector3f::Zero();
};

float Logit(float alpha) { return std::log(alpha / (1.0f - alpha)); }

// A cloud of `splats` with SH degree `degree` (f_rest filled with the splat's index / 100).
PointCloud Cloud(const std::vector<Splat>& splats, int degree = 0) {
    const int64_t n = static_cast<int64_t>(splats.size());
    const int rest = NumSHRestCoeffs(degree);
    Tensor positions({n, 3}, Dtype::Float32), scale({n, 3}, Dtype::Float32),
        rot({n, 4}, Dtype::Float32), opacity({n, 1}, Dtype::Float32), dc({n, 3}, Dtype::Float32),
        f_rest({n, rest, 3}, Dtype::Float32);
    for (int64_t i = 0; i < n; ++i) {
        const Splat& s = splats[i];
        for (int c = 0; c < 3; ++c) {
            positions.Data<float>()[3 * i + c] = s.position[c];
            scale.Data<float>()[3 * i + c] = s.scale[c];
            dc.Data<float>()[3 * i + c] = s.dc[c];
        }
        const float q[] = {s.rot.w(), s.rot.x(), s.rot.y(), s.rot.z()};
        for (int c = 0; c < 4; ++c) rot.Data<float>()[4 * i + c] = q[c];
        opacity.Data<float>()[i] = Logit(s.alpha);
        for (int k = 0; k < 3 * rest; ++k) f_rest.Data<float>()[3 * rest * i + k] = i / 100.0f;
    }
    PointCloud cloud(positions);
    cloud.SetPointAttr(gs_attr::kScale, scale);
    cloud.SetPointAttr(gs_attr::kRot, rot);
    cloud.SetPointAttr(gs_attr::kOpacity, opacity);
    cloud.SetPointAttr(gs_attr::kFDc, dc);
    if (rest > 0) cloud.SetPointAttr(gs_attr::kFRest, f_rest);
    return cloud;
}

std::vector<Splat> RandomSplats(std::mt19937& rng, int n) {
    std::uniform_real_distribution<float> position(-5.f, 5.f), size(0.01f, 0.3f),
        alpha(0.05f, 0.95f), color(-1.f, 1.f);
    std::vector<Splat> splats;
    for (int i = 0; i < n; ++i) {
        Splat s;
        s.position = {position(rng), position(rng), position(rng)};
        s.scale = {size(rng), size(rng), size(rng)};
        s.rot = Eigen::Quaternionf(RandomRotation(rng).cast<float>());
        s.alpha = alpha(rng);
        s.dc = {color(rng), color(rng), color(rng)};
        splats.push_back(s);
    }
    // Duplicates: splats that share a Morton code are grouped eight to a node.
    for (int i = 0; i < 20; ++i) splats.push_back(splats[0]);
    return splats;
}

// The root's Gaussian: covariance from scale and rotation, opacity from the logit.
struct Merged {
    Eigen::Vector3d mean;
    Eigen::Matrix3d covariance;
    double alpha;
    Eigen::Vector3d dc;
};
Merged Root(const SplatHierarchy& h) {
    const GaussianSplatArrays a = h.inner.GetGaussianSplatArrays();
    const int64_t k = h.NumInner() - 1;
    Merged m;
    m.mean = Eigen::Vector3d(a.positions[3 * k], a.positions[3 * k + 1], a.positions[3 * k + 2]);
    const Eigen::Matrix3d r =
        Eigen::Quaterniond(a.rot[4 * k], a.rot[4 * k + 1], a.rot[4 * k + 2], a.rot[4 * k + 3])
            .toRotationMatrix();
    const Eigen::Vector3d s(a.scale[3 * k], a.scale[3 * k + 1], a.scale[3 * k + 2]);
    m.covariance = r * s.cwiseProduct(s).asDiagonal() * r.transpose();
    m.alpha = 1.0 / (1.0 + std::exp(-double(a.opacity[k])));
    m.dc = Eigen::Vector3d(a.f_dc[3 * k], a.f_dc[3 * k + 1], a.f_dc[3 * k + 2]);
    return m;
}

// float32 storage of the merged Gaussian: relative errors of ~1e-7 per value, a few ulps
// through the eigen decomposition and the quaternion; 1e-5 leaves a margin of ~30x.
constexpr double kTolerance = 1e-5;

TEST(SplatHierarchy, TwoSeparatedGaussiansMergeToTheirMoments) {
    // Isotropic s at x = -d and +d, equal opacity: mean 0, covariance diag(s^2 + d^2, s^2,
    // s^2), colour the average, opacity 1 - (1 - a s^2 / (A B))^2 with A B = sqrt(s^2 + d^2) s.
    const float s = 0.2f, d = 1.0f, a = 0.6f;
    Splat left{{-d, 0, 0}, {s, s, s}}, right{{d, 0, 0}, {s, s, s}};
    left.alpha = right.alpha = a;
    left.dc = {1, 0, 0};
    right.dc = {0, 1, 0};
    const SplatHierarchy h = BuildSplatHierarchy(Cloud({left, right}));
    ASSERT_EQ(h.NumInner(), 1);
    const Merged m = Root(h);
    EXPECT_LT(m.mean.norm(), kTolerance);
    const Eigen::Matrix3d expected =
        Eigen::Vector3d(s * s + d * d, s * s, s * s).asDiagonal().toDenseMatrix();
    EXPECT_LT((m.covariance - expected).norm() / expected.norm(), kTolerance);
    EXPECT_LT((m.dc - Eigen::Vector3d(0.5, 0.5, 0)).norm(), kTolerance);
    const double share = double(s) * s / (std::sqrt(double(s) * s + d * d) * s);
    const double alpha = 1.0 - std::pow(1.0 - a * share, 2);
    EXPECT_NEAR(m.alpha, alpha, kTolerance);
}

TEST(SplatHierarchy, WeightsAreOpacityTimesVolume) {
    // Two anisotropic, rotated Gaussians of different opacity and size: the mean and
    // colour are weighted by alpha * sx * sy * sz, the covariance adds the means' spread.
    std::mt19937 rng(7);
    Splat p{{0.3f, -0.2f, 1.0f}, {0.3f, 0.1f, 0.05f}}, q{{-0.4f, 0.5f, 0.8f}, {0.1f, 0.1f, 0.1f}};
    p.rot = Eigen::Quaternionf(RandomRotation(rng).cast<float>());
    q.rot = Eigen::Quaternionf(RandomRotation(rng).cast<float>());
    p.alpha = 0.9f;
    q.alpha = 0.2f;
    p.dc = {1, 2, 3};
    q.dc = {-1, 0, 1};
    const SplatHierarchy h = BuildSplatHierarchy(Cloud({p, q}));
    const auto covariance = [](const Splat& g) {
        const Eigen::Matrix3d r = g.rot.cast<double>().toRotationMatrix();
        const Eigen::Vector3d s = g.scale.cast<double>();
        return Eigen::Matrix3d(r * s.cwiseProduct(s).asDiagonal() * r.transpose());
    };
    const double wp = p.alpha * p.scale.cast<double>().prod();
    const double wq = q.alpha * q.scale.cast<double>().prod();
    const double fp = wp / (wp + wq), fq = wq / (wp + wq);
    const Eigen::Vector3d mean = fp * p.position.cast<double>() + fq * q.position.cast<double>();
    const Eigen::Vector3d dp = p.position.cast<double>() - mean;
    const Eigen::Vector3d dq = q.position.cast<double>() - mean;
    const Eigen::Matrix3d cov =
        fp * (covariance(p) + dp * dp.transpose()) + fq * (covariance(q) + dq * dq.transpose());
    const Merged m = Root(h);
    EXPECT_LT((m.mean - mean).norm(), kTolerance);
    EXPECT_LT((m.covariance - cov).norm() / cov.norm(), kTolerance);
    EXPECT_LT((m.dc - (fp * p.dc.cast<double>() + fq * q.dc.cast<double>())).norm(), kTolerance);
}

TEST(SplatHierarchy, StackedCopiesComposeLikeLayers) {
    // Identical Gaussians: the same Gaussian, opacity 1 - (1 - a)^3 (capped at 0.99).
    Splat g{{1, 2, 3}, {0.3f, 0.2f, 0.1f}};
    g.rot = Eigen::Quaternionf(Eigen::AngleAxisf(0.7f, Eigen::Vector3f(1, 1, 0).normalized()));
    g.alpha = 0.4f;
    const SplatHierarchy h = BuildSplatHierarchy(Cloud({g, g, g}));
    ASSERT_EQ(h.NumInner(), 1);  // one Morton code: one node of three children
    const Merged m = Root(h);
    const Eigen::Matrix3d r = g.rot.cast<double>().toRotationMatrix();
    const Eigen::Vector3d s = g.scale.cast<double>();
    const Eigen::Matrix3d cov = r * s.cwiseProduct(s).asDiagonal() * r.transpose();
    EXPECT_LT((m.mean - g.position.cast<double>()).norm(), kTolerance);
    EXPECT_LT((m.covariance - cov).norm() / cov.norm(), kTolerance);
    EXPECT_NEAR(m.alpha, 1.0 - std::pow(1.0 - 0.4, 3), kTolerance);
}

TEST(SplatHierarchy, EveryLeafHasOneParentAndInnerNodesTwoToEightChildren) {
    std::mt19937 rng(3);
    const PointCloud cloud = Cloud(RandomSplats(rng, 500), 3);
    const SplatHierarchy h = BuildSplatHierarchy(cloud);
    EXPECT_EQ(h.num_leaves, 520);
    EXPECT_EQ(h.inner.NumPoints(), h.NumInner());
    EXPECT_EQ(h.inner.GaussianSplatGetSHOrder(), 3);
    std::vector<int> parents(h.NumNodes(), 0);
    for (int64_t k = 0; k < h.NumInner(); ++k) {
        const int64_t count = h.child_offsets[k + 1] - h.child_offsets[k];
        EXPECT_GE(count, 2);
        EXPECT_LE(count, 8);
        for (int64_t c = h.child_offsets[k]; c < h.child_offsets[k + 1]; ++c) {
            EXPECT_LT(h.children[c], h.num_leaves + k);  // children come first: a tree
            ++parents[h.children[c]];
        }
    }
    for (int64_t i = 0; i < h.NumNodes(); ++i) {
        EXPECT_EQ(parents[i], i == h.Root() ? 0 : 1) << "node " << i;
    }
    // One splat: the root is that splat.
    const SplatHierarchy one = BuildSplatHierarchy(Cloud({Splat{{0, 0, 0}, {1, 1, 1}}}));
    EXPECT_EQ(one.NumInner(), 0);
    EXPECT_EQ(one.Root(), 0);
    EXPECT_THROW(BuildSplatHierarchy(PointCloud()), core::Open3DError);
}

TEST(SplatHierarchy, CutsPartitionTheLeavesWithinTheBudget) {
    std::mt19937 rng(5);
    const PointCloud cloud = Cloud(RandomSplats(rng, 500), 1);
    const SplatHierarchy h = BuildSplatHierarchy(cloud);
    std::vector<int64_t> parent(h.NumNodes(), -1);
    for (int64_t k = 0; k < h.NumInner(); ++k) {
        for (int64_t c = h.child_offsets[k]; c < h.child_offsets[k + 1]; ++c) {
            parent[h.children[c]] = h.num_leaves + k;
        }
    }
    SplatCutView view;
    view.world_to_camera(2, 3) = 10.0;  // the cloud 5..15 in front of the camera
    view.focal_px = 800.0;
    for (const int64_t budget : {1, 2, 7, 50, 300, 519}) {
        SCOPED_TRACE("budget " + std::to_string(budget));
        const std::vector<int64_t> cut = CutSplatHierarchy(h, view, budget);
        EXPECT_LE(static_cast<int64_t>(cut.size()), budget);
        EXPECT_TRUE(std::is_sorted(cut.begin(), cut.end()));
        std::vector<char> in_cut(h.NumNodes(), 0);
        for (int64_t node : cut) in_cut[node] = 1;
        for (int64_t leaf = 0; leaf < h.num_leaves; ++leaf) {
            int covering = 0;
            for (int64_t node = leaf; node != -1; node = parent[node]) covering += in_cut[node];
            ASSERT_EQ(covering, 1) << "leaf " << leaf;
        }
        if (budget >= 50) {
            EXPECT_GT(static_cast<int64_t>(cut.size()), budget / 2);  // the budget is used
        }
    }
    EXPECT_THROW(CutSplatHierarchy(h, view, 0), core::Open3DError);
}

// The budget goes to what the view sees: 100 splats in front of the camera, 100 behind it
// and 100 in front but beside the image's frustum. With a budget of 110 every splat in view
// is a leaf of the cut and the other two clusters keep at most 10 nodes; with every leaf's
// budget all are leaves. (Before the frustum test, nodes behind the camera had a negative
// depth and counted as the largest: opened first.)
TEST(SplatHierarchy, CutsRefineOnlyWhatTheViewSees) {
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<Splat> splats;
    const auto cluster = [&](float x, float z) {
        for (int i = 0; i < 100; ++i) {
            splats.push_back(
                Splat{{x + unit(rng), unit(rng) - 0.5f, z + unit(rng)}, {0.02f, 0.02f, 0.02f}});
        }
    };
    cluster(-0.5f, 5.0f);   // in view: x / z within +-0.2 of the image's +-0.5
    cluster(-0.5f, -6.0f);  // behind the camera
    cluster(50.0f, 5.0f);   // x / z ~ 10: far beside the frustum
    const SplatHierarchy h = BuildSplatHierarchy(Cloud(splats));
    SplatCutView view;  // camera at the origin looking down +z
    view.focal_px = 100.0;
    view.width = view.height = 100;
    view.fx = view.fy = 100.0;
    view.cx = view.cy = 49.5;
    const std::vector<int64_t> cut = CutSplatHierarchy(h, view, 110);
    const auto in_view = [](int64_t node) { return node < 100; };
    EXPECT_EQ(std::count_if(cut.begin(), cut.end(), in_view), 100);
    EXPECT_LE(cut.size(), 110u);
    EXPECT_EQ(CutSplatHierarchy(h, view, 300).size(), 300u);
    // Without the image only the camera's back bounds the cut: the cluster beside the
    // frustum competes with the one in view, and the one behind the camera stays closed.
    view.width = view.height = 0;
    const std::vector<int64_t> unbounded = CutSplatHierarchy(h, view, 110);
    EXPECT_LT(std::count_if(unbounded.begin(), unbounded.end(), in_view), 100);
    for (int64_t node : unbounded) EXPECT_FALSE(node >= 100 && node < 200) << node;
}

TEST(SplatHierarchy, ABudgetOfEveryLeafGivesTheSourceCloud) {
    std::mt19937 rng(11);
    const PointCloud cloud = Cloud(RandomSplats(rng, 300), 2);
    const SplatHierarchy h = BuildSplatHierarchy(cloud);
    SplatCutView view;
    view.world_to_camera(2, 3) = 10.0;
    view.focal_px = 500.0;
    for (const int64_t budget : {h.num_leaves, h.num_leaves + 100}) {
        const std::vector<int64_t> cut = CutSplatHierarchy(h, view, budget);
        ASSERT_EQ(static_cast<int64_t>(cut.size()), h.num_leaves);
        EXPECT_TRUE(ExtractSplatNodes(h, cloud, cut) == cloud);
    }
    // A coarse cut carries inner nodes with the source's attributes.
    const PointCloud coarse = ExtractSplatNodes(h, cloud, CutSplatHierarchy(h, view, 20));
    EXPECT_LE(coarse.NumPoints(), 20);
    EXPECT_EQ(coarse.GaussianSplatGetSHOrder(), 2);
    EXPECT_THROW(ExtractSplatNodes(h, cloud, {h.NumNodes()}), core::Open3DError);
}

TEST(SplatHierarchy, AHierarchyOfAnotherSceneIsRefusedNotRead) {
    // A stale .lod beside a scene (RandomSplats adds 20 copies of the first splat): the
    // same count at another SH degree made ExtractSplatNodes
    // copy f_rest rows the hierarchy does not have (a crash); the same count and degree with
    // other positions drew another scene's inner nodes.
    std::mt19937 rng(17);
    const std::vector<Splat> splats = RandomSplats(rng, 16);
    const PointCloud scene = Cloud(splats, 3);
    const SplatHierarchy of_sh0 = BuildSplatHierarchy(Cloud(splats, 0));
    ASSERT_GT(of_sh0.NumInner(), 0);
    EXPECT_NE(HierarchySourceMismatch(of_sh0, scene).find("SH degree 0"), std::string::npos)
        << HierarchySourceMismatch(of_sh0, scene);
    EXPECT_THROW(ExtractSplatNodes(of_sh0, scene, {of_sh0.Root()}), core::Open3DError);
    const SplatHierarchy of_fewer =
        BuildSplatHierarchy(Cloud({splats.begin(), splats.end() - 1}, 3));
    const std::string fewer = std::to_string(scene.NumPoints() - 1) + " leaves";
    EXPECT_NE(HierarchySourceMismatch(of_fewer, scene).find(fewer), std::string::npos)
        << HierarchySourceMismatch(of_fewer, scene);
    std::vector<Splat> moved = splats;
    moved[7].position.x() += 1e-3;
    const SplatHierarchy of_moved = BuildSplatHierarchy(Cloud(moved, 3));
    EXPECT_NE(HierarchySourceMismatch(of_moved, scene).find("another scene"), std::string::npos);
    EXPECT_THROW(ExtractSplatNodes(of_moved, scene, {of_moved.Root()}), core::Open3DError);
    // Its own scene fits; a hierarchy without a fingerprint (a version 1 file) is checked by
    // count and degree alone.
    const SplatHierarchy own = BuildSplatHierarchy(scene);
    EXPECT_EQ(HierarchySourceMismatch(own, scene), "");
    EXPECT_EQ(own.scene_fingerprint, SplatSceneFingerprint(scene));
    SplatHierarchy unknown = of_moved;
    unknown.scene_fingerprint = 0;
    EXPECT_EQ(HierarchySourceMismatch(unknown, scene), "");
}

TEST(SplatHierarchy, ReportsProgressByLeavesPlaced) {
    // 2^17 + 20 splats: reports at 1/2 and 1 (every 2^16 leaves), then 1 at the end; never
    // going back.
    std::mt19937 rng(13);
    const PointCloud cloud = Cloud(RandomSplats(rng, 1 << 17));
    std::vector<double> fractions;
    {
        core::ScopedProgressCallback progress([&](const char* stage, double fraction) {
            EXPECT_STREQ(stage, "level of detail");
            fractions.push_back(fraction);
        });
        BuildSplatHierarchy(cloud);
    }
    ASSERT_GE(fractions.size(), 3u);
    EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
    EXPECT_NEAR(fractions.front(), 65536.0 / (131072 + 20), 1e-12);
    EXPECT_EQ(fractions.back(), 1.0);
}

}  // namespace
}  // namespace geometry
}  // namespace t
}  // namespace open3d
