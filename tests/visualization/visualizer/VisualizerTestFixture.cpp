#include "visualization/visualizer/VisualizerTestFixture.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <thread>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanBackendRegistry.h"
#include "visualization/rendering/gaussian_splat/cpu/SplatTestScene.h"

namespace open3d {
namespace tests {

rendering::FilamentEngine* VisualizerTest::engine_ = nullptr;
rendering::FilamentRenderer* VisualizerTest::renderer_ = nullptr;
std::string VisualizerTest::skip_reason_;

void VisualizerTest::SetUpTestSuite() {
    skip_reason_ = rendering::FilamentUnavailableReason(rendering::GlPlatform::kGlx);
    if (!skip_reason_.empty()) return;
    rendering::vulkan::RegisterVulkanBackend();
    try {
        rendering::CreateGaussianSplatBackend("vulkan");
    } catch (const core::Open3DError& e) {
        skip_reason_ = std::string("no Vulkan device: ") + e.what();
        return;
    }
    engine_ = new rendering::FilamentEngine();
    renderer_ = new rendering::FilamentRenderer(*engine_);
}

void VisualizerTest::TearDownTestSuite() {
    delete renderer_;
    delete engine_;
    renderer_ = nullptr;
    engine_ = nullptr;
}

void VisualizerTest::SetUp() {
    if (!skip_reason_.empty()) OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE(skip_reason_);
}

void VisualizerTest::TearDown() {
    if (vis_) {
        EXPECT_EQ(
            rendering::vulkan::GetValidationProblemCount(vis_->GetScene().GetScene().GetBackend()),
            0u);
    }
    vis_.reset();
}

visualization::Visualizer& VisualizerTest::MakeVisualizer(int width, int height, bool show_settings,
                                                          double interactive_frame_ms) {
    visualization::VisualizerOptions options;
    options.title = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    options.width = width;
    options.height = height;
    options.show_settings = show_settings;
    options.interactive_frame_ms = interactive_frame_ms;
    return MakeVisualizer(options);
}

visualization::Visualizer& VisualizerTest::MakeVisualizer(
    visualization::VisualizerOptions options) {
    options.title = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    options.scene.backend = "vulkan";
    vis_ = std::make_unique<visualization::Visualizer>(*renderer_, options);
    return *vis_;
}

void VisualizerTest::AddWallAndSphere(visualization::Visualizer& vis) {
    std::vector<TestSplat> splats;
    const int n = 12;
    const double half = 3.0, step = 2.0 * half / (n - 1);
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            TestSplat s;
            s.position = Eigen::Vector3d(-half + i * step, -half + j * step, 4.0);
            s.scale = Eigen::Vector3d(step, step, 0.01);
            s.opacity = 0.95;
            s.color = Eigen::Vector3d(0.1, 0.2, 0.9);
            splats.push_back(s);
        }
    }
    vis.AddGeometry("wall", MakeCloud(splats));
    t::geometry::TriangleMesh sphere = t::geometry::TriangleMesh::CreateSphere(0.5, 30);
    sphere.Translate(Eigen::Vector3d(0, 0, 2));
    rendering::MaterialRecord red;
    red.base_color = Eigen::Vector4f(1, 0, 0, 1);
    vis.AddGeometry("sphere", sphere, red);
    vis.SetBackground(Eigen::Vector4f(0.2f, 0.3f, 0.4f, 1.0f));
    vis.ResetCamera();
}

bool VisualizerTest::WaitForSize(visualization::Visualizer& vis, int width, int height) {
    // A minute: only a window that never resizes takes that long, however busy the machine.
    for (int i = 0; i < 6000; ++i) {
        vis.PollEvents();
        if (vis.GetWidth() == width && vis.GetHeight() == height) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
}

int64_t CountRed(const t::geometry::Image& rgb) {
    const uint8_t* p = rgb.Data<uint8_t>();
    const int64_t c = rgb.GetChannels();
    int64_t red = 0;
    for (int64_t i = 0; i < rgb.NumPixels(); ++i) {
        red += p[c * i] >= 80 && p[c * i + 1] <= 8 && p[c * i + 2] <= 8;
    }
    return red;
}

void PressKey(visualization::Visualizer& vis, int key) {
    vis.OnKey(key, true, false, 0);
    vis.OnKey(key, false, false, 0);
}

double MeanAbsDiff(const t::geometry::Image& a, const t::geometry::Image& b, int64_t x0, int64_t y0,
                   int64_t x1, int64_t y1) {
    const int64_t w = a.GetCols(), c = a.GetChannels();
    const uint8_t* pa = a.Data<uint8_t>();
    const uint8_t* pb = b.Data<uint8_t>();
    double sum = 0.0;
    int64_t count = 0;
    for (int64_t y = y0; y < y1; ++y) {
        for (int64_t x = x0; x < x1; ++x) {
            for (int64_t k = 0; k < c; ++k) {
                const int64_t i = (y * w + x) * c + k;
                sum += std::abs(int(pa[i]) - int(pb[i]));
                ++count;
            }
        }
    }
    return count ? sum / count : 0.0;
}

}  // namespace tests
}  // namespace open3d
