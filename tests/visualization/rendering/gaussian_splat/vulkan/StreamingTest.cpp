// Streaming a paged splat file into the Vulkan backend's pool (SetScenePool, WriteSceneSplats,
// SplatStreamer): with a pool too small for the whole scene the picture converges to the CPU
// reference's render of the whole scene, pages are evicted when the view moves and read again
// when it returns, and a scene cut into many small pages renders as the same scene in one.
#include <gtest/gtest.h>

#include <string>

#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/ImageMetrics.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/t/io/SplatPageFile.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatMerge.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamer.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"
#include "t/io/RandomSplatCloud.h"
#include "visualization/rendering/gaussian_splat/StreamingTestUtility.h"
#include "visualization/rendering/gaussian_splat/vulkan/VulkanTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;

using Streaming = VulkanTest;

// Steps until nothing the view wants is missing, drawing each step's pool on `backend`.
// Returns the steps taken.
int StreamUntilComplete(SplatStreamer& streamer, vulkan::GaussianSplatVulkanBackend& backend,
                        const camera::PinholeCamera& cam, int64_t reads_per_step) {
    for (int steps = 1; steps <= 1000; ++steps) {
        const SplatStreamStep step = streamer.Step(SplatCutViewOf(cam), reads_per_step);
        backend.ApplyStreamStep(step);
        if (step.pages_wanted == 0) return steps;
    }
    ADD_FAILURE() << "did not converge";
    return 1000;
}

double Psnr(const RenderOutput& a, const RenderOutput& b) {
    return t::geometry::ComputeImageErrorMetrics(a.color, b.color, 1.0, 1.0 / 255.0).psnr_db;
}

TEST_F(Streaming, ATinyPoolConvergesToTheWholeScenesImageAsTheViewMoves) {
    const std::string path = DataPath("playbot/playbot_31k.ply");
    if (!FileExists(path)) OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE("playbot_31k.ply is absent");
    t::geometry::PointCloud one;
    t::io::ReadPointCloud(path, one);
    const camera::PinholeCamera a =
        camera::ReadCamerasJson(DataPath("playbot/cameras.json")).at(3).camera.Resized(96, 72);
    // A second copy 50 units to the first camera's right, seen by a camera moved as far: each
    // camera sees one copy. (Farther, float rounding of the copy's centres makes many splats
    // of equal view depth, whose order then follows the pool's slots, not the scene's.)
    const Eigen::Vector3d right = a.GetRotation().row(0).transpose();
    t::geometry::PointCloud two = one;
    two.Translate(50.0 * right);
    const t::geometry::PointCloud scene = MergeGaussianSplatClouds({&one, &two});
    camera::PinholeCamera b = a;
    b.world_to_camera.topRightCorner<3, 1>() -= a.GetRotation() * (50.0 * right);

    const std::string paged = TempDir() + "/two_playbots.gspages";
    t::io::WriteSplatPages(paged, scene, t::geometry::BuildSplatHierarchy(scene), 1024);
    const t::io::SplatPageFile file(paged);
    // The pages each view needs on its own; the pool holds the larger, not both.
    const int64_t need_a = PagesTheViewNeeds(file, a), need_b = PagesTheViewNeeds(file, b);
    const int64_t pool = std::max(need_a, need_b);
    ASSERT_LT(pool, need_a + need_b - 2);
    ASSERT_LT(pool, file.NumPages() * 6 / 10);

    SplatStreamer streamer(file, pool, file.NumLeaves());
    auto backend = MakeBackend();
    backend->SetScenePool(streamer.PoolSplats(), file.ShDegree(), file.CenterMin(),
                          file.CenterMax());
    {
        // The first step draws the root's page: a coarse picture of the first copy.
        backend->ApplyStreamStep(streamer.Step(SplatCutViewOf(a), 0));
        const RenderOutput coarse = backend->Render(a, {});
        const RenderOutput ref = cpu::RenderReference(scene, a, {});
        EXPECT_LT(Psnr(coarse, ref), 30.0);
    }
    for (const camera::PinholeCamera& cam : {a, b, a}) {
        const int steps = StreamUntilComplete(streamer, *backend, cam, 8);
        const RenderOutput streamed = backend->Render(cam, {});
        const RenderOutput ref = cpu::RenderReference(scene, cam, {});
        auto plain = MakeBackend();
        plain->SetScene(scene);
        const RenderOutput whole = plain->Render(cam, {});
        SCOPED_TRACE("after " + std::to_string(steps) + " steps");
        // What the whole scene uploaded at once gives: the first camera's image bit for bit
        // (infinite PSNR), the second's at 124.8 dB, where float rounding of the copy's
        // centres 50 units out makes splats of equal view depth, ordered by their slots.
        EXPECT_GE(Psnr(streamed, whole), 120.0);
        // And the reference: the renderer's own accuracy here is 104.3 and 92.5 dB (the
        // whole scene uploaded at once gives the same), nothing over 1/255.
        const auto m =
            t::geometry::ComputeImageErrorMetrics(streamed.color, ref.color, 1.0, 1.0 / 255.0);
        EXPECT_GE(m.psnr_db, 90.0);
        EXPECT_EQ(m.fraction_over_threshold, 0.0);
        EXPECT_EQ(streamed.stats.error_flags, 0u);
    }
    EXPECT_GT(streamer.Evictions(), 0);
    EXPECT_GT(streamer.PagesRead(), need_a + need_b);
}

// A 64 x 64 camera 40 units in front of t::io::RandomCloud's splats.
camera::PinholeCamera RandomCloudView() {
    camera::PinholeCamera cam;
    cam.width = cam.height = 64;
    cam.fx = cam.fy = 50.0;
    cam.cx = cam.cy = 31.5;
    cam.world_to_camera(2, 3) = 40.0;
    return cam;
}

// Streams `scene` cut into pages of `capacity` nodes with room for every page and renders
// `cam` once nothing is missing.
RenderOutput StreamedImage(const t::geometry::PointCloud& scene,
                           const t::geometry::SplatHierarchy& hierarchy, int64_t capacity,
                           const camera::PinholeCamera& cam,
                           vulkan::GaussianSplatVulkanBackend& backend,
                           bool compact_storage = false) {
    const std::string paged = TempDir() + "/scene_" + std::to_string(capacity) + ".gspages";
    t::io::WriteSplatPages(paged, scene, hierarchy, capacity);
    const t::io::SplatPageFile file(paged);
    SplatStreamer streamer(file, file.NumPages(), file.NumLeaves());
    backend.SetScenePool(streamer.PoolSplats(), file.ShDegree(), file.CenterMin(), file.CenterMax(),
                         compact_storage);
    StreamUntilComplete(streamer, backend, cam, 1024);
    if (capacity == 8) {
        EXPECT_GT(file.NumPages(), hierarchy.NumNodes() / 8);  // pages of one to eight nodes
    }
    RenderConfig config;
    config.compact_storage = compact_storage;
    return backend.Render(cam, config);
}

TEST_F(Streaming, ManySmallPagesRenderAsOnePage) {
    // Random splats: no two share a view depth, so the order the depth sort gives is the
    // same whatever slots the pool holds them in, and the images must be equal bit for bit.
    const t::geometry::PointCloud scene = t::io::RandomCloud(3000, 1, 7);
    const t::geometry::SplatHierarchy hierarchy = t::geometry::BuildSplatHierarchy(scene);
    const camera::PinholeCamera cam = RandomCloudView();
    auto backend = MakeBackend();
    const RenderOutput small = StreamedImage(scene, hierarchy, 8, cam, *backend);
    const RenderOutput one = StreamedImage(scene, hierarchy, hierarchy.NumNodes(), cam, *backend);
    EXPECT_EQ(small.stats.num_visible, one.stats.num_visible);
    EXPECT_EQ(small.stats.num_tile_entries, one.stats.num_tile_entries);
    EXPECT_EQ(t::geometry::ComputeMaxAbsError(small.color, one.color), 0.0);
    EXPECT_EQ(t::geometry::ComputeMaxAbsError(small.depth_expected, one.depth_expected), 0.0);
    // And what both show is the scene (the accuracy bound of the test above).
    EXPECT_GE(Psnr(small, cpu::RenderReference(scene, cam, {})), 90.0);
}

TEST_F(Streaming, ACompactPoolDrawsAsTheSceneStoredCompact) {
    // The pages packed at half precision into the pool: the image of the whole scene stored
    // compact, bit for bit (random splats: no two share a view depth).
    const t::geometry::PointCloud scene = t::io::RandomCloud(3000, 1, 7);
    const camera::PinholeCamera cam = RandomCloudView();
    auto backend = MakeBackend();
    const RenderOutput streamed =
        StreamedImage(scene, t::geometry::BuildSplatHierarchy(scene), 64, cam, *backend, true);
    RenderConfig compact;
    compact.compact_storage = true;
    auto plain = MakeBackend();
    plain->SetScene(scene);
    const RenderOutput whole = plain->Render(cam, compact);
    EXPECT_GT(streamed.stats.num_visible, 1000);
    EXPECT_EQ(streamed.stats.num_visible, whole.stats.num_visible);
    EXPECT_EQ(t::geometry::ComputeMaxAbsError(streamed.color, whole.color), 0.0);
    EXPECT_EQ(t::geometry::ComputeMaxAbsError(streamed.depth_expected, whole.depth_expected), 0.0);
    // Half precision is not the exact image (the pool really is compact), and a frame that
    // asks for float32 is refused: there is no host copy to re-pack.
    EXPECT_GT(t::geometry::ComputeMaxAbsError(streamed.color, plain->Render(cam, {}).color), 0.0);
    ExpectErrorContaining([&] { backend->Render(cam, {}); },
                          "keeps the precision it was made at (half precision)");
}

TEST_F(Streaming, WritesIntoAPlainSceneDrawAsTheSceneWrittenWhole) {
    // Writes of 50, then 200, then 50 splats: the staging kept between writes grows and is
    // then reused for less. Random splats: no two share a view depth, so equal scenes give
    // equal images bit for bit.
    using t::io::RandomCloud;
    const auto p = RandomCloud(500, 1, 1), q = RandomCloud(200, 1, 2), r = RandomCloud(250, 1, 3),
               u = RandomCloud(50, 1, 4);
    const auto q2 = RandomCloud(200, 1, 5), u2 = RandomCloud(50, 1, 6), u3 = RandomCloud(50, 1, 7);
    const camera::PinholeCamera cam = RandomCloudView();
    auto written = MakeBackend();
    written->SetScene(MergeGaussianSplatClouds({&p, &q, &r, &u}));
    written->WriteSceneSplats(950, u2);
    written->WriteSceneSplats(500, q2);
    written->WriteSceneSplats(950, u3);
    auto whole = MakeBackend();
    whole->SetScene(MergeGaussianSplatClouds({&p, &q2, &r, &u3}));
    RenderConfig compact;
    compact.compact_storage = true;
    // The compact frame re-packs the written scene from its host copy, which must follow.
    for (const RenderConfig& config : {RenderConfig{}, compact}) {
        const RenderOutput a = written->Render(cam, config), b = whole->Render(cam, config);
        EXPECT_GT(a.stats.num_visible, 500);
        EXPECT_EQ(a.stats.num_visible, b.stats.num_visible);
        EXPECT_EQ(t::geometry::ComputeMaxAbsError(a.color, b.color), 0.0);
        EXPECT_EQ(t::geometry::ComputeMaxAbsError(a.depth_expected, b.depth_expected), 0.0);
    }
}

TEST_F(Streaming, WritesOutsideThePoolOrOfAnotherDegreeAreRefused) {
    auto backend = MakeBackend();
    backend->SetScenePool(100, 1, Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
    const std::string path = DataPath("playbot/playbot_31k.ply");
    if (!FileExists(path)) OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE("playbot_31k.ply is absent");
    t::geometry::PointCloud scene;
    t::io::ReadPointCloud(path, scene);
    // playbot_31k has SH degree 3; the pool degree 1.
    EXPECT_THROW(backend->WriteSceneSplats(0, scene), core::Open3DError);
    EXPECT_THROW(backend->SetScenePool(0, 1, Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()),
                 core::Open3DError);
    // The pool has no host copy to re-pack at half precision.
    camera::PinholeCamera cam;
    cam.width = cam.height = 16;
    cam.fx = cam.fy = 16.0;
    cam.cx = cam.cy = 7.5;
    RenderConfig compact;
    compact.compact_storage = true;
    EXPECT_NO_THROW(backend->Render(cam, {}));
    EXPECT_THROW(backend->Render(cam, compact), core::Open3DError);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
