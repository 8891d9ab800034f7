// One Filament engine and renderer per test binary; each test opens its own small visible
// Visualizer window on it. Skips with the reason where no X server (run under xvfb-run) or
// no Vulkan device exists; fails instead in CI (CI=true). Scene: a wall of blue splats at z = 4 and
// a red sphere mesh in front of it at z = 2; the camera looks along +z (world -y up, the 3DGS
// convention).
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "open3d/t/geometry/Image.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/filament/FilamentRenderer.h"
#include "open3d/visualization/visualizer/Visualizer.h"

namespace open3d {
namespace tests {

namespace rendering = visualization::rendering;

class VisualizerTest : public ::testing::Test {
protected:
    static void SetUpTestSuite();
    static void TearDownTestSuite();
    void SetUp() override;
    void TearDown() override;

    /// A visible window of width x height on the shared engine (owned until TearDown,
    /// which checks that the Vulkan validation layer stayed quiet).
    /// `interactive_frame_ms` 0: every frame at full resolution (the tests compare pictures).
    visualization::Visualizer& MakeVisualizer(int width = 240, int height = 160,
                                              bool show_settings = false,
                                              double interactive_frame_ms = 0.0);
    /// A visible window with these options (title and backend set here).
    visualization::Visualizer& MakeVisualizer(visualization::VisualizerOptions options);
    /// Adds "wall" (splats) and "sphere" (mesh), in that order, and fits the camera.
    void AddWallAndSphere(visualization::Visualizer& vis);
    /// Polls events until the framebuffer is width x height (false after about a minute).
    bool WaitForSize(visualization::Visualizer& vis, int width, int height);

    static rendering::FilamentEngine* engine_;
    static rendering::FilamentRenderer* renderer_;
    static std::string skip_reason_;
    std::unique_ptr<visualization::Visualizer> vis_;
};

/// A key pressed and released, as GLFW reports it to the window.
void PressKey(visualization::Visualizer& vis, int key);
/// Pixels whose colour is the sphere's red (g and b near 0, r clearly up).
int64_t CountRed(const t::geometry::Image& rgb);
/// Mean absolute difference per channel over the rectangle [x0, x1) x [y0, y1) of two
/// UInt8 images of the same size.
double MeanAbsDiff(const t::geometry::Image& a, const t::geometry::Image& b, int64_t x0, int64_t y0,
                   int64_t x1, int64_t y1);

}  // namespace tests
}  // namespace open3d
