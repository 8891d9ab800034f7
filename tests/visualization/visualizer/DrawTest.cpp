// Open3D's draw(): the convenience opens its own engine and window, adds the objects by
// name, fits the camera and runs (here for a few frames).
#include <gtest/gtest.h>

#include "TestUtility.h"

#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/visualizer/Visualizer.h"

namespace open3d {
namespace tests {
namespace {

TEST(DrawFunction, ShowsObjectsForTheRequestedFrames) {
    const std::string reason = visualization::rendering::FilamentUnavailableReason();
    if (!reason.empty()) OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE(reason);
    std::vector<visualization::DrawObject> objects(2);
    objects[0].name = "splats";
    objects[0].geometry = visualization::rendering::CreateDefaultGaussianSplatScene();
    objects[1].name = "sphere";
    objects[1].geometry = t::geometry::TriangleMesh::CreateSphere(0.3, 12);
    objects[1].visible = false;
    visualization::VisualizerOptions options;
    options.width = 96;
    options.height = 64;
    options.scene.backend = "auto";  // the placeholder where no Vulkan device exists
    int frames = 0;
    visualization::RunOptions run;
    run.continuous = true;
    run.max_frames = 3;
    run.before_frame = [&] { ++frames; };
    visualization::Draw(objects, options, run);
    EXPECT_EQ(frames, 3);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
