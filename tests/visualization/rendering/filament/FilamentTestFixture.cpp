#include "visualization/rendering/filament/FilamentTestFixture.h"

#include <algorithm>
#include <cmath>

#include "TestUtility.h"
#include "open3d/core/Exception.h"

#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanBackendRegistry.h"
#include "visualization/rendering/gaussian_splat/cpu/SplatTestScene.h"

namespace open3d {
namespace tests {

rendering::FilamentEngine* FilamentTest::engine_ = nullptr;
rendering::FilamentRenderer* FilamentTest::renderer_ = nullptr;
std::string FilamentTest::skip_reason_;

void FilamentTest::SetUpTestSuite() {
    skip_reason_ = rendering::FilamentUnavailableReason();
    if (!skip_reason_.empty()) return;
    engine_ = new rendering::FilamentEngine();
    renderer_ = new rendering::FilamentRenderer(*engine_);
    rendering::vulkan::RegisterVulkanBackend();
    try {
        rendering::CreateGaussianSplatBackend("vulkan");
    } catch (const core::Open3DError& e) {
        skip_reason_ = std::string("no Vulkan device: ") + e.what();
    }
}

void FilamentTest::TearDownTestSuite() {
    delete renderer_;
    delete engine_;
    renderer_ = nullptr;
    engine_ = nullptr;
}

void FilamentTest::SetUp() {
    if (!skip_reason_.empty()) OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE(skip_reason_);
}

void FilamentTest::TearDown() {
    EXPECT_EQ(ValidationProblems(), 0u);
    views_.clear();  // their targets belong to the scenes' backends
    scenes_.clear();
    open3d_scenes_.clear();
}

rendering::FilamentScene& FilamentTest::MakeScene(const std::string& backend) {
    scenes_.push_back(
        std::make_unique<rendering::FilamentScene>(engine_->GetEngine(), renderer_->GetMaterials(),
                                                   rendering::CreateGaussianSplatBackend(backend)));
    return *scenes_.back();
}

rendering::FilamentView& FilamentTest::MakeView(const camera::PinholeCamera& camera,
                                                rendering::SplatSharing sharing) {
    views_.push_back(
        std::make_unique<rendering::FilamentView>(*engine_, renderer_->GetMaterials(), sharing));
    views_.back()->SetCamera(camera);
    return *views_.back();
}

rendering::Open3DScene& FilamentTest::MakeOpen3DScene(
    const rendering::Open3DSceneOptions& options) {
    open3d_scenes_.push_back(std::make_unique<rendering::Open3DScene>(*renderer_, options));
    return *open3d_scenes_.back();
}

rendering::RenderOutput FilamentTest::RenderHeadless(const t::geometry::PointCloud& cloud,
                                                     const camera::PinholeCamera& camera) {
    auto backend = rendering::CreateGaussianSplatBackend("vulkan");
    backend->SetScene(cloud);
    rendering::RenderOutput out = backend->Render(camera, rendering::RenderConfig{});
    headless_problems_ += rendering::vulkan::GetValidationProblemCount(*backend);
    return out;
}

uint64_t FilamentTest::ValidationProblems() const {
    uint64_t problems = headless_problems_;
    for (const auto& scene : open3d_scenes_) {
        problems += rendering::vulkan::GetValidationProblemCount(scene->GetScene().GetBackend());
    }
    for (const auto& scene : scenes_) {
        problems += rendering::vulkan::GetValidationProblemCount(scene->GetBackend());
    }
    return problems;
}

std::string SharingTestName(const ::testing::TestParamInfo<rendering::SplatSharing>& info) {
    switch (info.param) {
        case rendering::SplatSharing::kZeroCopy:
            return "ZeroCopy";
        case rendering::SplatSharing::kHostCopy:
            return "HostCopy";
        case rendering::SplatSharing::kAuto:
            break;
    }
    return "Auto";
}

camera::PinholeCamera MakeFilamentTestCamera(int width, int height) {
    camera::PinholeCamera camera;
    camera.width = width;
    camera.height = height;
    camera.fx = camera.fy = 0.9 * width;
    camera.cx = (width - 1) / 2.0;
    camera.cy = (height - 1) / 2.0;
    return camera;
}

t::geometry::PointCloud MakeSplatWall(double depth, double half, int n,
                                      const Eigen::Vector3d& rgb) {
    std::vector<TestSplat> splats;
    const double step = 2.0 * half / (n - 1);
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            TestSplat s;
            s.position = Eigen::Vector3d(-half + i * step, -half + j * step, depth);
            s.scale = Eigen::Vector3d(step, step, 0.01);
            s.opacity = 0.95;
            s.color = rgb;
            splats.push_back(s);
        }
    }
    return MakeCloud(splats);
}

t::geometry::PointCloud MakeSplatBlob(double x, double y, double depth, double radius,
                                      const Eigen::Vector3d& rgb) {
    std::vector<TestSplat> splats;
    for (int j = -1; j <= 1; ++j) {
        for (int i = -1; i <= 1; ++i) {
            TestSplat s;
            s.position = Eigen::Vector3d(x + i * radius / 2, y + j * radius / 2, depth);
            s.scale = Eigen::Vector3d(radius / 2, radius / 2, 0.01);
            s.opacity = 0.9;
            s.color = rgb;
            splats.push_back(s);
        }
    }
    return MakeCloud(splats);
}

std::array<int, 4> ExpectedOver(const float* s, const Eigen::Vector4f& background) {
    std::array<int, 4> out{};
    for (int c = 0; c < 4; ++c) {
        const double v = s[c] + (1.0 - s[3]) * background[c];
        out[c] = static_cast<int>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
    }
    return out;
}

void AddRedSphere(rendering::FilamentScene& scene, const std::string& name) {
    t::geometry::TriangleMesh sphere = t::geometry::TriangleMesh::CreateSphere(kSphereRadius, 40);
    sphere.Translate(Eigen::Vector3d(0, 0, kSphereZ));
    rendering::MaterialRecord material;
    material.base_color = Eigen::Vector4f(1, 0, 0, 1);
    scene.AddGeometry(name, sphere, material);
}

void AddSplatsAroundRedSphere(rendering::FilamentScene& scene) {
    scene.AddGeometry("wall", MakeSplatWall(4.0, 3.0, 24, Eigen::Vector3d(0.1, 0.2, 0.9)));
    scene.AddGeometry("front", MakeSplatBlob(0.2, 0.0, 1.2, 0.08, Eigen::Vector3d(0.1, 0.9, 0.2)));
    AddRedSphere(scene);
}

double SphereDepthTolerance(double cos_incidence) {
    return cos_incidence < 0.3 ? -1.0 : 2e-3 / cos_incidence;
}

double SphereDepthAt(const camera::PinholeCamera& camera, double u, double v,
                     double* cos_incidence) {
    // Ray (x, y, 1) * t against |p - c| = r with c = (0, 0, kSphereZ); depth = t.
    const Eigen::Vector3d d((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
    const Eigen::Vector3d c(0, 0, kSphereZ);
    const double a = d.squaredNorm(), b = -2.0 * d.dot(c);
    const double k = c.squaredNorm() - kSphereRadius * kSphereRadius;
    const double disc = b * b - 4 * a * k;
    if (disc < 0) return 0.0;
    const double t = (-b - std::sqrt(disc)) / (2 * a);
    if (cos_incidence) *cos_incidence = std::abs((t * d - c).normalized().dot(d.normalized()));
    return t;
}

}  // namespace tests
}  // namespace open3d
