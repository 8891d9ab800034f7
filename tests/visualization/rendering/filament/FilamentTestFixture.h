// One Filament engine and renderer per test binary (each ctest entry is its own process),
// skipping with the reason where no X server (run under xvfb-run) or no Vulkan device
// exists (failing instead in CI: CI=true), and small scenes built in code: a wall of splats behind,
// a red sphere, splats in front. The camera looks along +z from the origin.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <string>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/filament/FilamentRenderer.h"
#include "open3d/visualization/rendering/filament/FilamentScene.h"
#include "open3d/visualization/rendering/filament/FilamentView.h"
#include "open3d/visualization/rendering/filament/Open3DScene.h"

namespace open3d {
namespace tests {

namespace rendering = visualization::rendering;

class FilamentTest : public ::testing::Test {
protected:
    static void SetUpTestSuite();
    static void TearDownTestSuite();
    void SetUp() override;
    void TearDown() override;

    /// A scene drawn by `backend` ("vulkan", "cpu" or "placeholder"), owned by the fixture
    /// until TearDown (which checks the validation counts, then destroys views and scenes).
    rendering::FilamentScene& MakeScene(const std::string& backend = "vulkan");
    rendering::FilamentView& MakeView(
        const camera::PinholeCamera& camera,
        rendering::SplatSharing sharing = rendering::SplatSharing::kAuto);
    /// An Open3DScene on the shared renderer, owned by the fixture like MakeScene's.
    rendering::Open3DScene& MakeOpen3DScene(const rendering::Open3DSceneOptions& options = {});
    /// The headless Vulkan renderer's image of `cloud` (no Filament), black background.
    rendering::RenderOutput RenderHeadless(const t::geometry::PointCloud& cloud,
                                           const camera::PinholeCamera& camera);
    /// Validation problems of every Vulkan backend this test made (must stay 0).
    uint64_t ValidationProblems() const;

    static rendering::FilamentEngine* engine_;
    static rendering::FilamentRenderer* renderer_;
    static std::string skip_reason_;
    std::vector<std::unique_ptr<rendering::FilamentScene>> scenes_;
    std::vector<std::unique_ptr<rendering::FilamentView>> views_;
    std::vector<std::unique_ptr<rendering::Open3DScene>> open3d_scenes_;
    uint64_t headless_problems_ = 0;
};

/// Test-name suffix of a SplatSharing parameter ("ZeroCopy", "HostCopy", "Auto").
std::string SharingTestName(const ::testing::TestParamInfo<rendering::SplatSharing>& info);

/// Camera at the origin looking along +z, fx = fy = 0.9 * width, principal point at the
/// image centre.
camera::PinholeCamera MakeFilamentTestCamera(int width, int height);

/// A wall of n x n overlapping splats of `rgb` in the plane z = `depth`, covering
/// [-half, half]^2, opacity 0.95, degree 0.
t::geometry::PointCloud MakeSplatWall(double depth, double half, int n, const Eigen::Vector3d& rgb);

/// A few splats of `rgb` around (x, y) in the plane z = depth (a small blob), opacity 0.9.
t::geometry::PointCloud MakeSplatBlob(double x, double y, double depth, double radius,
                                      const Eigen::Vector3d& rgb);

/// round(255 * (s + (1 - s_a) * background)) per channel: the expected RGBA8 of splats
/// (premultiplied float RGBA) over an opaque background.
std::array<int, 4> ExpectedOver(const float* splat_rgba, const Eigen::Vector4f& background);

/// The red sphere of the occlusion tests (radius 0.5 at (0, 0, 2), flat colour).
constexpr double kSphereRadius = 0.5;
constexpr double kSphereZ = 2.0;
void AddRedSphere(rendering::FilamentScene& scene, const std::string& name = "sphere");
/// The red sphere between a half-transparent blue splat wall behind it (z = 4) and a green
/// splat blob in front of it (z = 1.2): splats over, under and beside a mesh.
void AddSplatsAroundRedSphere(rendering::FilamentScene& scene);

/// Depth of the sphere's surface along the ray of pixel (u, v), or 0 when the ray misses;
/// `cos_incidence` (optional) gets |cos| of the angle between the ray and the normal.
double SphereDepthAt(const camera::PinholeCamera& camera, double u, double v,
                     double* cos_incidence = nullptr);

/// Tolerance of a rasterized sphere's depth against SphereDepthAt: the 40-segment UV
/// sphere lies inside the true one by up to r (1 - cos(pi / 40) cos(pi / 80)) = 1.9e-3
/// radially, which a ray sees divided by the cosine of its incidence angle; pixels with
/// cos < 0.3 (the silhouette) are not compared (returns < 0).
double SphereDepthTolerance(double cos_incidence);

}  // namespace tests
}  // namespace open3d
