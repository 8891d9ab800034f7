// Open3D's draw(): the convenience opens its own engine and window, adds the objects by
// name, fits the camera and runs (here for a few frames).
#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "TestUtility.h"

#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/t/io/SplatPageFile.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/visualizer/Visualizer.h"

namespace open3d {
namespace tests {
namespace {

// A 96 x 64 window on `backend`, drawn continuously for three frames counted in `frames`.
std::pair<visualization::VisualizerOptions, visualization::RunOptions> ThreeFrames(
    const std::string& backend, int& frames) {
    visualization::VisualizerOptions options;
    options.width = 96;
    options.height = 64;
    options.scene.backend = backend;
    visualization::RunOptions run;
    run.continuous = true;
    run.max_frames = 3;
    run.before_frame = [&frames] { ++frames; };
    return {options, run};
}

TEST(DrawFunction, ShowsObjectsForTheRequestedFrames) {
    const std::string reason = visualization::rendering::FilamentUnavailableReason(
        visualization::rendering::GlPlatform::kGlx);
    if (!reason.empty()) OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE(reason);
    std::vector<visualization::DrawObject> objects(2);
    objects[0].name = "splats";
    objects[0].geometry = visualization::rendering::CreateDefaultGaussianSplatScene();
    objects[1].name = "sphere";
    objects[1].geometry = t::geometry::TriangleMesh::CreateSphere(0.3, 12);
    objects[1].visible = false;
    int frames = 0;
    // "auto": the placeholder where no Vulkan device exists.
    const auto [options, run] = ThreeFrames("auto", frames);
    visualization::Draw(objects, options, run);
    EXPECT_EQ(frames, 3);
}

// A stream among the objects: the viewer streams the paged file (the default scene's) and
// draws; a path that is no paged file is refused before the loop runs.
TEST(DrawFunction, StreamsAPagedFile) {
    const std::string reason = visualization::rendering::FilamentUnavailableReason(
        visualization::rendering::GlPlatform::kGlx);
    if (!reason.empty()) OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE(reason);
    const t::geometry::PointCloud scene =
        visualization::rendering::CreateDefaultGaussianSplatScene();
    const std::string dir = TempDir();
    t::io::WriteSplatPages(dir + "/default.gspages", scene, t::geometry::BuildSplatHierarchy(scene),
                           64);
    std::vector<visualization::DrawObject> objects(1);
    visualization::StreamedSplats stream;
    stream.path = dir + "/default.gspages";
    objects[0].geometry = stream;
    int frames = 0;
    const auto [options, run] = ThreeFrames("vulkan", frames);
    visualization::Draw(objects, options, run);
    EXPECT_EQ(frames, 3);
    stream.path = dir + "/missing.gspages";
    objects[0].geometry = stream;
    frames = 0;
    ExpectErrorContaining(
        [&, &options = options, &run = run] { visualization::Draw(objects, options, run); },
        "missing.gspages");
    EXPECT_EQ(frames, 0);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
