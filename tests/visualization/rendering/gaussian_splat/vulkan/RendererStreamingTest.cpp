// GaussianSplatRenderer::StreamSplats: a paged file streamed through the renderer's frames
// (Prepare takes the worker's steps, the geometry stage gives it the view) converges to the
// whole scene's image as the view moves through a pool too small for both views, reports its
// progress, and is refused where it cannot work.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/ImageMetrics.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/SplatPageFile.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatMerge.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatRenderer.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamSession.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"
#include "t/io/RandomSplatCloud.h"
#include "visualization/rendering/gaussian_splat/StreamingTestUtility.h"
#include "visualization/rendering/gaussian_splat/vulkan/VulkanTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;

using RendererStreaming = VulkanTest;

// A 64 x 64 camera 40 units in front of x = `x`, looking along +z.
camera::PinholeCamera CameraAt(double x) {
    camera::PinholeCamera cam;
    cam.width = cam.height = 64;
    cam.fx = cam.fy = 50.0;
    cam.cx = cam.cy = 31.5;
    cam.world_to_camera(0, 3) = -x;
    cam.world_to_camera(2, 3) = 40.0;
    return cam;
}

// Two random clusters 1000 units apart along x: each camera of CameraAt(0) and
// CameraAt(1000) sees one. The shift is along x only, so view depths stay those of the
// random draw: no two splats share one, and the depth order does not depend on the slots
// the pool holds them in.
t::geometry::PointCloud TwoClusters() {
    const t::geometry::PointCloud a = t::io::RandomCloud(1500, 1, 11);
    t::geometry::PointCloud b = t::io::RandomCloud(1500, 1, 12);
    b.Translate(Eigen::Vector3d(1000.0, 0.0, 0.0));
    return MergeGaussianSplatClouds({&a, &b});
}

// Draws frames of `cam` as a viewer does until the stream settles, sleeping 1 ms after a
// frame when no step waits; returns the last frame and counts the frames drawn.
RenderOutput DrawUntilSettled(GaussianSplatRenderer& renderer, const camera::PinholeCamera& cam,
                              int& frames) {
    RenderOutput out;
    for (frames = 1; frames <= 20000; ++frames) {
        renderer.Prepare();
        renderer.RenderGeometryStage(0, cam, {});
        renderer.RenderCompositeStage(0, out);
        if (renderer.GetStreamProgress()->settled) return out;
        if (!renderer.HasStreamNews()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ADD_FAILURE() << "the stream did not settle";
    return out;
}

TEST_F(RendererStreaming, ACompactStreamDrawsAtItsPoolsPrecision) {
    // Frames that leave RenderConfig::compact_storage off draw a compact stream at half
    // precision: the image of the whole scene stored compact.
    const t::geometry::PointCloud scene = TwoClusters();
    const std::string paged = TempDir() + "/two_clusters_compact.gspages";
    t::io::WriteSplatPages(paged, scene, t::geometry::BuildSplatHierarchy(scene), 64);
    SplatStreamOptions options;
    options.compact_storage = true;
    GaussianSplatRenderer renderer(MakeBackend());
    renderer.StreamSplats(paged, options);
    const camera::PinholeCamera cam = CameraAt(0.0);
    int frames = 0;
    const RenderOutput streamed = DrawUntilSettled(renderer, cam, frames);
    auto plain = MakeBackend();
    plain->SetScene(scene);
    RenderConfig compact;
    compact.compact_storage = true;
    const RenderOutput whole = plain->Render(cam, compact);
    EXPECT_GT(streamed.stats.num_visible, 500);
    EXPECT_EQ(streamed.stats.num_visible, whole.stats.num_visible);
    EXPECT_EQ(t::geometry::ComputeMaxAbsError(streamed.color, whole.color), 0.0);
}

TEST_F(RendererStreaming, FramesConvergeToTheWholeScenesImageAsTheViewMoves) {
    const t::geometry::PointCloud scene = TwoClusters();
    const std::string paged = TempDir() + "/two_clusters.gspages";
    t::io::WriteSplatPages(paged, scene, t::geometry::BuildSplatHierarchy(scene), 64);
    const camera::PinholeCamera a = CameraAt(0.0), b = CameraAt(1000.0);
    // The pages each view needs on its own; the pool holds the larger, not both.
    const t::io::SplatPageFile file(paged);
    const int64_t need_a = PagesTheViewNeeds(file, a), need_b = PagesTheViewNeeds(file, b);
    const int64_t pool = std::max(need_a, need_b);
    ASSERT_LT(pool, need_a + need_b - 2);
    SplatStreamOptions options;
    options.gpu_budget = static_cast<uint64_t>(
        std::ceil(double(pool * file.PageCapacity()) * StreamPoolBytesPerSplat(file.ShDegree())));
    options.reads_per_step = 4;

    GaussianSplatRenderer renderer(MakeBackend());
    renderer.StreamSplats(paged, options);
    ASSERT_TRUE(renderer.IsStreaming());
    EXPECT_TRUE(renderer.HasVisibleSplats());
    EXPECT_EQ(renderer.GetStreamProgress()->pool_pages, pool);
    EXPECT_FALSE(renderer.GetStreamProgress()->settled);  // no view yet
    auto plain = MakeBackend();
    plain->SetScene(scene);
    for (const camera::PinholeCamera& cam : {a, b, a}) {
        int frames = 0;
        const RenderOutput streamed = DrawUntilSettled(renderer, cam, frames);
        SCOPED_TRACE("after " + std::to_string(frames) + " frames");
        // The first frame of a view gives the worker the view; its pages show from a later
        // frame on (here the second: the worker read them all while lavapipe drew one).
        EXPECT_GE(frames, 2);
        const SplatStreamProgress p = *renderer.GetStreamProgress();
        EXPECT_EQ(p.pages_wanted, 0);
        EXPECT_FALSE(p.starved);
        EXPECT_TRUE(p.error.empty());
        EXPECT_NE(FormatStreamProgress(p).find("complete"), std::string::npos)
            << FormatStreamProgress(p);
        const RenderOutput whole = plain->Render(cam, {});
        EXPECT_EQ(streamed.stats.num_visible, whole.stats.num_visible);
        EXPECT_EQ(t::geometry::ComputeMaxAbsError(streamed.color, whole.color), 0.0);
    }
    const SplatStreamProgress p = *renderer.GetStreamProgress();
    EXPECT_GT(p.evictions, 0);
    EXPECT_GT(p.pages_read, need_a + need_b);
    EXPECT_LE(p.resident_pages, pool);
    // Frames of a settled view change nothing and ask the worker for nothing, and a second
    // view drawn in between (as a viewer's offscreen render) does not take the stream
    // along: the stream follows the first view.
    renderer.RenderGeometryStage(1, b, {});
    int frames = 0;
    DrawUntilSettled(renderer, a, frames);
    EXPECT_EQ(frames, 1);
    EXPECT_FALSE(renderer.HasStreamNews());
    // Once that view is released, the next view drawn leads.
    renderer.ReleaseView(0);
    const RenderOutput led = DrawUntilSettled(renderer, b, frames);
    EXPECT_EQ(t::geometry::ComputeMaxAbsError(led.color, plain->Render(b, {}).color), 0.0);
}

TEST_F(RendererStreaming, RefusalsLeaveTheRendererAsItWas) {
    const t::geometry::PointCloud scene = t::io::RandomCloud(300, 0, 5);
    const std::string dir = TempDir();  // (each call empties the folder)
    const std::string paged = dir + "/small.gspages";
    t::io::WriteSplatPages(paged, scene, t::geometry::BuildSplatHierarchy(scene), 64);
    GaussianSplatRenderer renderer(MakeBackend());
    renderer.AddCloud("cloud", scene);
    ExpectErrorContaining([&] { renderer.StreamSplats(paged); }, "remove them first");
    EXPECT_FALSE(renderer.IsStreaming());
    renderer.RemoveCloud("cloud");
    SplatStreamOptions tiny;
    tiny.gpu_budget = 1000;  // not one page of 64 splats
    ExpectErrorContaining([&] { renderer.StreamSplats(paged, tiny); }, "holds no page");
    ExpectErrorContaining([&] { renderer.StreamSplats(dir + "/missing.gspages"); }, "missing");
    EXPECT_FALSE(renderer.IsStreaming());
    // A budget above what one binding spans on lavapipe or an H200, but a file of a few
    // pages: a slot per page, no more (the device limit itself: SplatStreamSession tests).
    SplatStreamOptions huge;
    huge.gpu_budget = uint64_t(1) << 40;
    renderer.StreamSplats(paged, huge);
    EXPECT_EQ(renderer.GetStreamProgress()->pool_pages, renderer.GetStreamProgress()->file_pages);
    // A refused file leaves the stream running.
    ExpectErrorContaining([&] { renderer.StreamSplats(dir + "/missing.gspages"); }, "missing");
    EXPECT_TRUE(renderer.IsStreaming());
    ExpectErrorContaining([&] { renderer.AddCloud("cloud", scene); }, "StopStreaming first");
    EXPECT_FALSE(renderer.HasCloud("cloud"));
    EXPECT_TRUE(renderer.StopStreaming());
    EXPECT_FALSE(renderer.StopStreaming());
    EXPECT_FALSE(renderer.HasVisibleSplats());
    renderer.AddCloud("cloud", scene);  // clouds again after the stream
    renderer.RemoveCloud("cloud");
    renderer.StreamSplats(paged);
    renderer.Clear();  // ends the stream too
    EXPECT_FALSE(renderer.IsStreaming());
    // The CPU reference has no pool.
    GaussianSplatRenderer cpu("cpu");
    ExpectErrorContaining([&] { cpu.StreamSplats(paged); }, "'cpu' splat backend cannot stream");
    EXPECT_FALSE(cpu.IsStreaming());
}

}  // namespace
}  // namespace tests
}  // namespace open3d
