// Level of detail in the viewer (docs/viewer.md "Level of detail"): a cloud given its
// hierarchy is drawn exactly while the camera is still (every leaf: the same picture and the
// same pick as the cloud without one) and through cuts that follow VisualizerOptions::lod_target_ms
// while it moves. The target is one no device meets (1e-9 ms), so the cut shrinks to the root
// whatever the machine's speed; the waits are for the frames' own stats, with deadlines only a hang
// reaches.
#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/PointCloudIO.h"
#include "visualization/visualizer/VisualizerTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using VisualizerLod = VisualizerTest;

bool SameImage(const t::geometry::Image& a, const t::geometry::Image& b) {
    return a.GetRows() == b.GetRows() && a.GetCols() == b.GetCols() && a.AsTensor() == b.AsTensor();
}

TEST_F(VisualizerLod, StillFramesAreExactAndMovingOnesFollowTheTarget) {
    const std::string path = DataPath("playbot/playbot_31k.ply");
    if (!FileExists(path)) OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE("playbot_31k.ply is absent");
    t::geometry::PointCloud cloud;
    t::io::ReadPointCloud(path, cloud);
    const int64_t n = cloud.NumPoints();
    visualization::VisualizerOptions options;
    options.width = 160;
    options.height = 120;
    options.lod_target_ms = 1e-9;
    options.interactive_frame_ms = 0.0;  // moving frames at full size: comparable stats
    options.show_settings = false;       // the drag starts in the view, not on the panel
    visualization::Visualizer& vis = MakeVisualizer(options);
    vis.AddGeometry("scene", cloud);
    vis.ResetCamera();
    ASSERT_TRUE(vis.RenderFrame());
    const t::geometry::Image plain = vis.CaptureScreenImage();
    const auto plain_pick = vis.PickSplat(80, 60);
    ASSERT_TRUE(plain_pick.has_value());

    vis.SetSplatHierarchy("scene", std::make_shared<const t::geometry::SplatHierarchy>(
                                       t::geometry::BuildSplatHierarchy(cloud)));
    ASSERT_TRUE(vis.RenderFrame());
    if (vis.GetBackendName() != "vulkan") GTEST_SKIP() << "the CPU reference draws no hierarchy";
    EXPECT_EQ(vis.GetLastFrame().splat_stats.lod_cut_nodes, n) << "still: every leaf";
    EXPECT_TRUE(SameImage(vis.CaptureScreenImage(), plain));
    // Still, the cut lists every leaf in order: picking names the cloud's splats.
    const auto pick = vis.PickSplat(80, 60);
    ASSERT_TRUE(pick.has_value());
    EXPECT_EQ(pick->index, plain_pick->index);

    // A drag: moving for as long as the button is down, whatever the frames take.
    vis.OnCursorPos(80, 60);
    vis.OnMouseButton(GLFW_MOUSE_BUTTON_LEFT, true, 0);
    int64_t nodes = n;
    for (int f = 0; f < 40 && nodes > 1; ++f) {
        vis.OnCursorPos(80 + f + 1, 60);
        ASSERT_TRUE(vis.RenderFrame());
        nodes = vis.GetLastFrame().splat_stats.lod_cut_nodes;
    }
    EXPECT_EQ(nodes, 1) << "the budget halves each frame towards one node";
    vis.OnMouseButton(GLFW_MOUSE_BUTTON_LEFT, false, 0);
    // Still again (0.25 s after the last motion): every leaf.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (vis.GetLastFrame().splat_stats.lod_cut_nodes != n &&
           std::chrono::steady_clock::now() < deadline) {
        ASSERT_TRUE(vis.RenderFrame());
    }
    EXPECT_EQ(vis.GetLastFrame().splat_stats.lod_cut_nodes, n);

    // Replacing the cloud drops its hierarchy; a hierarchy of another cloud is refused.
    EXPECT_THROW(
        vis.SetSplatHierarchy(
            "scene", std::make_shared<const t::geometry::SplatHierarchy>(
                         t::geometry::BuildSplatHierarchy(cloud.SelectByIndex({0, 1, 2})))),
        core::Open3DError);
    EXPECT_THROW(vis.SetLodTargetMs(-1.0), core::Open3DError);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
