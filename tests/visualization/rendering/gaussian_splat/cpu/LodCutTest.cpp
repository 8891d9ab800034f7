// cpu::CutLikeGpu, the CPU mirror of the GPU level-of-detail cut, against a cut found
// another way: a walk from the root that opens a node while the smallest size bucket on
// its path lies above the threshold. The threshold must be the lowest that fits the budget.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <map>

#include "GaussianSplatLodContract.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatLodPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/LodCut.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;
using t::geometry::SplatHierarchy;

// The cut when every node whose path's smallest bucket exceeds `threshold` opens, found by a
// depth-first walk from the root (kLodOpenAll: every node opens).
std::vector<int64_t> WalkCut(const SplatHierarchy& h, const camera::PinholeCamera& cam,
                             uint32_t threshold) {
    const t::geometry::GaussianSplatArrays inner = h.inner.GetGaussianSplatArrays();
    std::vector<int64_t> cut;
    std::function<void(int64_t, uint32_t)> walk = [&](int64_t node, uint32_t path_min) {
        if (node < h.num_leaves) {
            cut.push_back(node);
            return;
        }
        const int64_t k = node - h.num_leaves;
        const float* p = inner.positions + 3 * k;
        const float* s = inner.scale + 3 * k;
        const double center[3] = {p[0], p[1], p[2]};
        const double radius = 3.0 * std::max({std::abs(s[0]), std::abs(s[1]), std::abs(s[2])});
        const uint32_t bucket = std::min(path_min, cpu::LodSizeBucket(cam, center, radius));
        if (threshold != shader::kLodOpenAll && bucket <= threshold) {
            cut.push_back(node);
            return;
        }
        for (int64_t c = h.child_offsets[k]; c < h.child_offsets[k + 1]; ++c) {
            walk(h.children[c], bucket);
        }
    };
    walk(h.Root(), shader::kLodBuckets);
    std::sort(cut.begin(), cut.end());
    return cut;
}

TEST(LodCutMirror, IsTheLowestThresholdThatFitsTheBudget) {
    const t::geometry::PointCloud cloud = CreateDefaultGaussianSplatScene();
    const SplatHierarchy h = t::geometry::BuildSplatHierarchy(cloud);
    const int64_t n = h.num_leaves;
    ASSERT_GT(h.NumInner(), 100);
    const camera::PinholeCamera cam = GetDefaultSceneCamera().Resized(160, 120);
    int64_t previous = 0;
    std::map<uint32_t, int> thresholds;
    for (const uint64_t budget : {uint64_t(1), uint64_t(7), uint64_t(100), uint64_t(n / 3),
                                  uint64_t(n - 1), uint64_t(n), uint64_t(0)}) {
        SCOPED_TRACE("budget " + std::to_string(budget));
        const cpu::LodCutResult result = cpu::CutLikeGpu(h, cam, budget);
        ++thresholds[result.threshold];
        EXPECT_EQ(result.nodes, WalkCut(h, cam, result.threshold));
        const int64_t size = int64_t(result.nodes.size());
        if (budget > 0) {
            EXPECT_LE(size, int64_t(budget));
        }
        EXPECT_GE(size, previous);  // budgets rise: cuts never shrink
        previous = size;
        // One bucket lower would not fit (the threshold is the lowest that does).
        if (result.threshold != shader::kLodOpenAll && budget > 0) {
            const uint32_t lower =
                result.threshold == 0 ? shader::kLodOpenAll : result.threshold - 1;
            EXPECT_GT(int64_t(WalkCut(h, cam, lower).size()), int64_t(budget));
        }
        // Every leaf lies under exactly one node of the cut.
        std::vector<int> covered(size_t(n), 0);
        std::vector<std::vector<int64_t>> below(size_t(h.NumNodes()));
        for (int64_t i = 0; i < n; ++i) below[size_t(i)] = {i};
        for (int64_t k = 0; k < h.NumInner(); ++k) {
            for (int64_t c = h.child_offsets[k]; c < h.child_offsets[k + 1]; ++c) {
                const auto& leaves = below[size_t(h.children[c])];
                below[size_t(n + k)].insert(below[size_t(n + k)].end(), leaves.begin(),
                                            leaves.end());
            }
        }
        for (const int64_t node : result.nodes) {
            for (const int64_t leaf : below[size_t(node)]) ++covered[size_t(leaf)];
        }
        EXPECT_TRUE(std::all_of(covered.begin(), covered.end(), [](int c) { return c == 1; }));
    }
    // A budget of every leaf (or none) is the leaves themselves.
    const cpu::LodCutResult all = cpu::CutLikeGpu(h, cam, 0);
    EXPECT_EQ(all.threshold, shader::kLodOpenAll);
    ASSERT_EQ(int64_t(all.nodes.size()), n);
    EXPECT_EQ(all.nodes.back(), n - 1);
    EXPECT_GE(thresholds.size(), 4u);  // the budgets above picked different thresholds
}

TEST(LodCutMirror, NodesOutsideTheViewOpenLast) {
    const t::geometry::PointCloud cloud = CreateDefaultGaussianSplatScene();
    const SplatHierarchy h = t::geometry::BuildSplatHierarchy(cloud);
    const int64_t n = h.num_leaves;
    // The principal point a width to the right: the view sees the scene's left part only.
    camera::PinholeCamera cam = GetDefaultSceneCamera().Resized(160, 120);
    cam.cx += cam.width;
    // Opening everything in view (threshold 0) leaves nodes outside whole; exactly that many
    // nodes as the budget opens nothing more.
    const std::vector<int64_t> every_visible = WalkCut(h, cam, 0);
    ASSERT_LT(int64_t(every_visible.size()), n / 2);
    const cpu::LodCutResult in_view = cpu::CutLikeGpu(h, cam, every_visible.size());
    EXPECT_EQ(in_view.threshold, 0u);
    EXPECT_EQ(in_view.nodes, every_visible);
    // Turned around (180 degrees about the camera's y axis) the scene lies behind it: the
    // same budget opens almost nothing.
    camera::PinholeCamera away = cam;
    away.world_to_camera = Eigen::Vector4d(-1.0, 1.0, -1.0, 1.0).asDiagonal() * cam.world_to_camera;
    const cpu::LodCutResult behind = cpu::CutLikeGpu(h, away, every_visible.size());
    EXPECT_LT(behind.nodes.size() * 10, in_view.nodes.size());
}

TEST(LodPacking, TheCutWalksFromTheRootWhereItIsAskedOrMeasuredFaster) {
    const uint32_t big = kLodWalkMinInner, leaves = 2 * big;
    // Asked for: walks, unless the slots hold every leaf or there is no inner node.
    EXPECT_TRUE(WalksLodCut(LodCutSearch::kFromRoot, 10, 21, 20));
    EXPECT_FALSE(WalksLodCut(LodCutSearch::kFromRoot, 10, 21, 21));
    EXPECT_FALSE(WalksLodCut(LodCutSearch::kFromRoot, 0, 1, 1));
    EXPECT_FALSE(WalksLodCut(LodCutSearch::kEveryNode, big, leaves, 1000));
    // kAuto: large hierarchies, budgets up to a quarter of the inner nodes.
    EXPECT_TRUE(WalksLodCut(LodCutSearch::kAuto, big, leaves, big / 4));
    EXPECT_FALSE(WalksLodCut(LodCutSearch::kAuto, big, leaves, big / 4 + 1));
    EXPECT_FALSE(WalksLodCut(LodCutSearch::kAuto, big - 1, leaves, 1000));
}

TEST(LodPacking, EveryInnerNodeListsItsChildrenAndEveryChildItsParent) {
    // The GPU cut's mask pass reaches a leaf only through its parent's entry in the packed
    // children (GaussianLodNode::first_child, children): each node must be listed once, by
    // its parent, in the hierarchy's order.
    const SplatHierarchy h = t::geometry::BuildSplatHierarchy(CreateDefaultGaussianSplatScene());
    const PackedLodNodes packed = PackLodNodes(h);
    const int64_t n = h.num_leaves, total = h.NumNodes();
    ASSERT_EQ(int64_t(packed.nodes.size()), total);
    ASSERT_EQ(int64_t(packed.children.size()), total - 1);  // every node but the root
    std::vector<int> listed(size_t(total), 0);
    for (int64_t id = 0; id < total; ++id) {
        const shader::GaussianLodNode& node = packed.nodes[size_t(id)];
        if (id < n) {
            EXPECT_EQ(node.children, 0u);
            EXPECT_EQ(node.first_child, 0u);
            continue;
        }
        const int64_t k = id - n;
        ASSERT_EQ(node.first_child, uint32_t(h.child_offsets[size_t(k)]));
        ASSERT_EQ(node.children, uint32_t(h.child_offsets[size_t(k) + 1] - h.child_offsets[k]));
        for (uint32_t c = 0; c < node.children; ++c) {
            const uint32_t child = packed.children[node.first_child + c];
            ASSERT_EQ(int64_t(child), h.children[node.first_child + c]);
            ASSERT_LT(int64_t(child), id);  // children before parents
            EXPECT_EQ(packed.nodes[child].parent, uint32_t(id));
            ++listed[child];
        }
    }
    EXPECT_EQ(packed.nodes.back().parent, shader::kLodNoParent);
    EXPECT_EQ(std::count(listed.begin(), listed.end(), 1), total - 1);
    EXPECT_EQ(listed.back(), 0);  // the root
    // The walk from the root takes a step per level of inner nodes: the deepest inner node's
    // depth + 1, counted here by following parents up from every inner node.
    uint32_t levels = 0;
    for (int64_t id = n; id < total; ++id) {
        uint32_t depth = 1;
        for (uint32_t up = packed.nodes[size_t(id)].parent; up != shader::kLodNoParent;
             up = packed.nodes[up].parent) {
            ++depth;
        }
        levels = std::max(levels, depth);
    }
    EXPECT_GT(levels, 2u);
    EXPECT_EQ(packed.inner_levels, levels);
    // A hierarchy of one leaf has no inner level.
    const t::geometry::PointCloud one =
        t::geometry::ExtractSplatNodes(h, CreateDefaultGaussianSplatScene(), {0});
    EXPECT_EQ(PackLodNodes(t::geometry::BuildSplatHierarchy(one)).inner_levels, 0u);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
