// 100 to 800 resizes, then 200 to 1,800 offscreen renders with a moving camera, a second cloud
// added and removed, and the sphere shown and hidden: no crash, no validation message, no GPU
// error flag, and resident memory that stops growing (Filament, GL and Vulkan objects of old
// sizes and scenes are freed; on lavapipe device memory is host memory, so RSS covers GPU
// allocations too). OPEN3D_SOAK_FRAMES=N renders at least N frames.
//
// Resizes and frames carry a one-time memory cost that differs by machine and by run: this
// machine has measured +0.7, +0.6, +0.6, +0.6, +0.4 MiB over the first five blocks of 100
// resizes after warm-up, then nothing, and on another run nothing in the resizes but +10.4 and
// +3.0 MiB in the first two blocks of frames; CI once measured +13.5 MiB over the first 200
// resizes. A leak grows without end, a one-time cost stops, so both phases run in blocks until
// one block grows by less than 256 KiB: a leak of 2.6 KiB per resize or 1.3 KiB per frame never
// gets there (one 16x12 RGBA16F target of the smallest size is 1.5 KiB before driver overhead,
// one 32x24 RGBA8 image 3 KiB).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <string>

#include "visualization/rendering/filament/FilamentTestFixture.h"

namespace open3d {
namespace tests {
namespace {

// Resident set size in KiB from /proc/self/status.
int64_t ResidentKiB() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line)) {
        if (line.rfind("VmRSS:", 0) == 0) return std::stoll(line.substr(6));
    }
    return -1;
}

using FilamentSoak = FilamentTest;

TEST_F(FilamentSoak, ResizesAndRendersWithoutGrowth) {
    rendering::Open3DScene& scene = MakeOpen3DScene();
    scene.AddGeometry("wall", MakeSplatWall(4.0, 3.0, 12, Eigen::Vector3d(0.2, 0.4, 0.8)));
    AddRedSphere(scene.GetScene());
    const auto render_at = [&](int w, int h) {
        scene.SetupCamera(MakeFilamentTestCamera(w, h));
        const t::geometry::Image image = scene.RenderToImage();
        ASSERT_EQ(image.GetCols(), w);
        ASSERT_TRUE(scene.GetLastFrame().splats_drawn);
    };
    // Warm up every size once, with and without the sphere (the composite pipeline without
    // scene depth is compiled on first use).
    for (int i = 0; i < 20; ++i) {
        scene.ShowGeometry("sphere", i % 2 == 0);
        render_at(16 + (i % 10) * 4, 12 + (i % 7) * 2);
    }
    scene.ShowGeometry("sphere", true);
    const int64_t before = ResidentKiB();
    const int64_t builds = scene.GetView().GetTargetBuilds();
    constexpr int kBlock = 100, kMaxBlocks = 8;
    constexpr int64_t kQuietBlockKiB = 256;
    int blocks = 0;
    int64_t block_growth = 0;
    std::string growth_log;
    do {
        const int64_t block_start = ResidentKiB();
        for (int i = 0; i < kBlock; ++i) render_at(16 + (i % 10) * 4, 12 + (i % 7) * 2);
        block_growth = ResidentKiB() - block_start;
        growth_log += " +" + std::to_string(block_growth);
    } while (++blocks < kMaxBlocks && block_growth >= kQuietBlockKiB);
    EXPECT_EQ(scene.GetView().GetTargetBuilds() - builds, blocks * kBlock);  // all rebuilt
    EXPECT_LT(block_growth, kQuietBlockKiB)
        << "KiB per block of " << kBlock << " resizes:" << growth_log;
    scene.SetupCamera(MakeFilamentTestCamera(32, 24));
    scene.RenderToImage();
    const int64_t after_resizes = ResidentKiB();
    // Frames in blocks of one whole cycle of the scene changes below (200 frames), until one
    // block grows by less than kQuietBlockKiB, as the resizes do: a leak of 1.3 KiB per frame or
    // more never gets there (one 32x24 RGBA8 image is 3 KiB). OPEN3D_SOAK_FRAMES=N renders at
    // least N frames.
    const char* frames_env = std::getenv("OPEN3D_SOAK_FRAMES");
    constexpr int kFrameBlock = 200;
    const int min_frame_blocks =
        frames_env ? (std::atoi(frames_env) + kFrameBlock - 1) / kFrameBlock : 1;
    const int max_frame_blocks = std::max(min_frame_blocks, 9);
    const t::geometry::PointCloud blob = MakeSplatBlob(0.5, 0.2, 1.5, 0.1, {0.9, 0.9, 0.1});
    camera::LookAtCamera look_at;
    look_at.eye = Eigen::Vector3d(0, 0, 0);
    look_at.center = Eigen::Vector3d(0, 0, 4);
    look_at.up = Eigen::Vector3d(0, -1, 0);
    int frames = 0;
    int64_t frame_block_growth = 0;
    std::string frame_log;
    do {
        const int64_t block_start = ResidentKiB();
        for (int i = 0; i < kFrameBlock; ++i, ++frames) {
            if (i % 100 == 50) scene.ShowGeometry("sphere", i / 100 == 0);
            if (i % 100 == 25) scene.AddGeometry("blob", blob);
            if (i % 100 == 75) scene.RemoveGeometry("blob");
            scene.SetupCamera(camera::OrbitLookAt(look_at, 0.01 * i), 32, 24);
            scene.RenderToImage();
            ASSERT_EQ(scene.GetLastFrame().splat_stats.error_flags, 0u) << "frame " << frames;
        }
        frame_block_growth = ResidentKiB() - block_start;
        frame_log += " +" + std::to_string(frame_block_growth);
    } while (frames / kFrameBlock < max_frame_blocks &&
             (frames / kFrameBlock < min_frame_blocks || frame_block_growth >= kQuietBlockKiB));
    EXPECT_LT(frame_block_growth, kQuietBlockKiB)
        << "KiB per block of " << kFrameBlock << " frames:" << frame_log;
    // No bound on the total: the one-time cost (above) lands in the resizes on some runs and in
    // the first frames on others (+10.4 MiB, +3.0 MiB, then +64 KiB over blocks of 200 frames on
    // this machine once); a leak is what keeps growing block after block.
    const int64_t after = ResidentKiB();
    EXPECT_EQ(scene.GetLastFrame().splat_stats.error_flags, 0u);
    std::printf(
        "RSS %lld -> %lld (%d resizes; KiB per block:%s) -> %lld KiB (%d frames; KiB per "
        "block:%s)\n",
        (long long)before, (long long)after_resizes, blocks * kBlock, growth_log.c_str(),
        (long long)after, frames, frame_log.c_str());
}

}  // namespace
}  // namespace tests
}  // namespace open3d
