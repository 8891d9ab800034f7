// The design's example written its way: an OffscreenRenderer, a MaterialRecord with the
// shader "gaussianSplat" for a Gaussian cloud, a lit mesh beside it, RenderToImage and
// RenderToDepthImage. The picture must match a small golden (regenerate with
// OPEN3D_TEST_GENERATE_REFERENCE=1; on a mismatch actual.png and diff.png are written).
#include <gtest/gtest.h>

#include "GoldenImage.h"
#include "TestUtility.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/filament/OffscreenRenderer.h"
#include "visualization/rendering/filament/FilamentTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using SeedExample = FilamentTest;

TEST_F(SeedExample, OffscreenRendererWithMaterialRecordsMatchesItsGolden) {
    rendering::OffscreenRenderer renderer(*engine_, 48, 32);
    rendering::MaterialRecord splat;
    splat.shader = "gaussianSplat";
    splat.gaussian_splat_sh_degree = 0;
    renderer.GetScene()->AddGeometry(
        "splats", MakeSplatWall(4.0, 3.0, 16, Eigen::Vector3d(0.1, 0.2, 0.9)), splat);
    rendering::MaterialRecord lit;
    lit.shader = "defaultLit";
    lit.base_color = Eigen::Vector4f(0.9f, 0.4f, 0.1f, 1.0f);
    t::geometry::TriangleMesh box = t::geometry::TriangleMesh::CreateSphere(0.5, 24);
    box.Translate(Eigen::Vector3d(0.6, -0.2, 2.5));  // right of centre and up (y is down)
    renderer.GetScene()->AddGeometry("mesh", box, lit);
    renderer.GetScene()->SetBackground(Eigen::Vector4f(0.3f, 0.3f, 0.3f, 1.0f));
    EXPECT_EQ(renderer.GetScene()->GetSplatConfig().sh_degree, 0);  // from the material
    // Open3D's look-at form: from the origin along +z, y down in the image.
    renderer.SetupCamera(60.0f, Eigen::Vector3f(0, 0, 1), Eigen::Vector3f(0, 0, 0),
                         Eigen::Vector3f(0, -1, 0));
    const t::geometry::Image actual = renderer.RenderToImage();
    ASSERT_EQ(actual.GetChannels(), 3);
    ASSERT_EQ(actual.GetRows(), 32);
    ASSERT_EQ(actual.GetCols(), 48);

    // Reversed-Z depth: 1 / z times the near plane; the wall (z = 4) where it shows.
    const t::geometry::Image depth = renderer.RenderToDepthImage();
    const t::geometry::Image z = renderer.RenderToDepthImage(true);
    const float near = static_cast<float>(renderer.GetScene()->GetView().GetMeshNearPlane());
    EXPECT_NEAR(depth.At<float>(2, 2, 0), near / 4.0f, 1e-6f);  // top left: the wall
    EXPECT_NEAR(z.At<float>(2, 2, 0), 4.0f, 1e-3f);

    // 5 LSB per channel, as the other golden: RGBA16F sharing and other GPUs' float
    // rounding move splat pixels by 1-2; a moved mesh edge or lost lighting moves ~100.
    ExpectMatchesGolden(actual, "visualization/rendering/filament/golden/seed_example_48x32.png",
                        5.0);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
