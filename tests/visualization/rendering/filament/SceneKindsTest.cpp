// Every kind of geometry AddGeometry takes, in one scene: a plain point cloud (Filament
// points), a lit mesh (defaultLit) and Gaussian splats behind and in front of them. The
// splat composite must hide exactly what lies behind the points and the mesh: the frame is
// checked pixel by pixel against the CPU reference composited on the same Filament depth.
#include <gtest/gtest.h>

#include <cmath>

#include "open3d/core/Exception.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatMerge.h"
#include "visualization/rendering/filament/FilamentTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using rendering::FrameRequest;
using rendering::FrameResult;
using rendering::MaterialRecord;

// A dense square patch of yellow points in the plane z = 3, right of the sphere.
t::geometry::PointCloud MakePointPatch() {
    std::vector<float> xyz, rgb;
    for (int i = 0; i < 30; ++i) {
        for (int j = 0; j < 30; ++j) {
            xyz.insert(xyz.end(), {0.45f + 0.03f * i, -0.45f + 0.03f * j, 3.0f});
            rgb.insert(rgb.end(), {1.0f, 0.9f, 0.1f});
        }
    }
    t::geometry::PointCloud cloud;
    cloud.SetPointPositions(core::Tensor::FromVector(xyz, {900, 3}));
    cloud.SetPointAttr("colors", core::Tensor::FromVector(rgb, {900, 3}));
    return cloud;
}

void AddLitSphere(rendering::FilamentScene& scene) {
    t::geometry::TriangleMesh sphere = t::geometry::TriangleMesh::CreateSphere(kSphereRadius, 40);
    sphere.Translate(Eigen::Vector3d(0, 0, kSphereZ));
    MaterialRecord lit;
    lit.shader = rendering::kShaderDefaultLit;
    lit.base_color = Eigen::Vector4f(1, 0, 0, 1);
    scene.AddGeometry("sphere", sphere, lit);
}

const Eigen::Vector3f kLight = Eigen::Vector3f(1.0f, 0.0f, 1.0f).normalized();
constexpr float kAmbient = 0.25f;

TEST_F(FilamentTest, PointsLitMeshAndSplatsOccludeAsTheCpuReference) {
    const camera::PinholeCamera camera = MakeFilamentTestCamera(64, 48);
    const t::geometry::PointCloud wall =
        MakeSplatWall(4.0, 3.0, 24, Eigen::Vector3d(0.1, 0.2, 0.9));
    // In front of the points' lower half: stays visible over them.
    const t::geometry::PointCloud front =
        MakeSplatBlob(0.8, 0.3, 2.5, 0.1, Eigen::Vector3d(0.1, 0.9, 0.2));
    MaterialRecord points;
    points.point_size = 4.0f;

    // The meshes and points alone: their colour and their depth.
    rendering::FilamentScene& solids = MakeScene();
    AddLitSphere(solids);
    solids.AddGeometry("points", MakePointPatch(), points);
    solids.SetLighting(kLight, kAmbient);
    rendering::FilamentView& view = MakeView(camera);
    FrameRequest request;
    request.read_color = true;
    request.read_depth = true;
    const FrameResult alone = renderer_->Draw(solids, view, request);
    ASSERT_FALSE(alone.splats_drawn);

    rendering::FilamentScene& scene = MakeScene();
    AddLitSphere(scene);
    scene.AddGeometry("points", MakePointPatch(), points);
    scene.SetLighting(kLight, kAmbient);
    scene.AddGeometry("wall", wall);
    scene.AddGeometry("front", front);
    const FrameResult frame = renderer_->Draw(scene, view, request);
    ASSERT_TRUE(frame.splats_drawn);
    ASSERT_TRUE(frame.scene_depth_used);

    // The CPU reference: the same splats composited against the depth Filament drew.
    std::unique_ptr<rendering::GaussianSplatBackend> cpu =
        rendering::CreateGaussianSplatBackend("cpu");
    cpu->SetScene(rendering::MergeGaussianSplatClouds({&front, &wall}));
    rendering::CompositeInputs inputs;
    inputs.scene_depth = &alone.linear_depth;
    cpu->RenderGeometryStage(camera, rendering::RenderConfig{});
    rendering::RenderOutput reference;
    cpu->RenderCompositeStage(reference, inputs);

    const uint8_t* got = frame.color.Data<uint8_t>();
    const uint8_t* solid = alone.color.Data<uint8_t>();
    const float* z = alone.linear_depth.Data<float>();
    int hidden_by_sphere = 0, hidden_by_points = 0, in_front = 0, open = 0;
    for (int64_t i = 0; i < camera.width * camera.height; ++i) {
        const int u = int(i % camera.width), v = int(i / camera.width);
        const float* s = reference.color.Data<float>() + 4 * i;
        // Splats "over" the solids' colour; 1 LSB: the splat colour reaches Filament as
        // RGBA16F (relative error <= 2^-10) and GPU and CPU sums differ by ~1e-6.
        for (int c = 0; c < 4; ++c) {
            const double want = std::lround(
                255.0 * std::clamp(s[c] + (1.0 - s[3]) * solid[4 * i + c] / 255.0, 0.0, 1.0));
            EXPECT_NEAR(got[4 * i + c], want, 1) << "pixel " << u << "," << v << " channel " << c;
        }
        if (z[i] > 0.0f && s[3] == 0.0f) {
            // Behind a solid and nothing in front: exactly the solid's colour.
            for (int c = 0; c < 4; ++c)
                EXPECT_EQ(got[4 * i + c], solid[4 * i + c]) << u << "," << v;
            (std::abs(z[i] - 3.0f) < 1e-3f ? hidden_by_points : hidden_by_sphere) += 1;
        } else if (z[i] > 0.0f && s[3] > 0.5f) {
            ++in_front;
        } else if (z[i] == 0.0f) {
            ++open;
        }
    }
    // Each case is met often enough that a wrong rule would show.
    EXPECT_GT(hidden_by_sphere, 100);
    EXPECT_GT(hidden_by_points, 100);
    EXPECT_GT(in_front, 5);
    EXPECT_GT(open, 500);
}

// defaultLit follows its formula: base * (ambient + (1 - ambient) * max(0, n . -l)), with
// n the sphere's analytic normal at the pixel's ray hit.
TEST_F(FilamentTest, DefaultLitShadesByTheDirectionalLightAndAmbient) {
    const camera::PinholeCamera camera = MakeFilamentTestCamera(64, 48);
    rendering::FilamentScene& scene = MakeScene("placeholder");
    AddLitSphere(scene);
    scene.SetLighting(kLight, kAmbient);
    rendering::FilamentView& view = MakeView(camera);
    FrameRequest request;
    request.read_color = true;
    const FrameResult frame = renderer_->Draw(scene, view, request);
    const uint8_t* rgba = frame.color.Data<uint8_t>();
    const Eigen::Vector3d c(0, 0, kSphereZ);
    int checked = 0;
    double sum_error = 0.0;
    for (int v = 0; v < camera.height; ++v) {
        for (int u = 0; u < camera.width; ++u) {
            double cos_incidence = 0.0;
            const double t = SphereDepthAt(camera, u, v, &cos_incidence);
            if (t <= 0.0 || cos_incidence < 0.3) continue;  // off the sphere or at its rim
            const Eigen::Vector3d d((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
            const Eigen::Vector3d n = (t * d - c).normalized();
            const double diffuse = std::max(0.0, n.dot(-kLight.cast<double>()));
            const double want = 255.0 * (kAmbient + (1.0 - kAmbient) * diffuse);
            const int i = v * camera.width + u;
            // 8 LSB: the 40-segment sphere's interpolated vertex normals deviate from the
            // analytic one by up to ~2.3 degrees (0.04 in n . l, 0.75 * 0.04 * 255 = 7.7).
            EXPECT_NEAR(rgba[4 * i + 0], want, 8.0) << u << "," << v;
            EXPECT_EQ(rgba[4 * i + 1], 0) << u << "," << v;
            sum_error += std::abs(rgba[4 * i + 0] - want);
            ++checked;
        }
    }
    EXPECT_GT(checked, 200);
    // Mean error well under the bound: the shading follows the formula, not just roughly.
    EXPECT_LT(sum_error / checked, 2.5);
}

// The default light is a headlight: it turns with the camera, so the side of the sphere a
// camera sees is lit the same from the front and from behind. A world-frame light stays.
TEST_F(FilamentTest, DefaultLightFollowsTheCameraAndWorldLightStays) {
    const camera::PinholeCamera front = MakeFilamentTestCamera(64, 48);
    camera::PinholeCamera back = front;  // turned 180 degrees about y, at z = 4
    back.world_to_camera.topLeftCorner<3, 3>() = Eigen::Vector3d(-1, 1, -1).asDiagonal();
    back.world_to_camera.topRightCorner<3, 1>() = Eigen::Vector3d(0, 0, 4);
    rendering::FilamentScene& scene = MakeScene("placeholder");
    AddLitSphere(scene);
    rendering::FilamentView& front_view = MakeView(front);
    rendering::FilamentView& back_view = MakeView(back);
    FrameRequest request;
    request.read_color = true;
    const size_t centre = 4 * (size_t(24) * 64 + 32);
    const auto red_at_centre = [&](rendering::FilamentView& view) {
        return int(renderer_->Draw(scene, view, request).color.Data<uint8_t>()[centre]);
    };
    const int headlight_front = red_at_centre(front_view);
    const int headlight_back = red_at_centre(back_view);
    // n . -l = 1 / |(0.3, 0.5, 1)| = 0.864 at the centre: 255 (0.25 + 0.75 0.864) = 229.
    EXPECT_NEAR(headlight_front, 229, 8);  // 8: interpolated normals, as above
    EXPECT_NEAR(headlight_back, headlight_front, 2);
    scene.SetLighting(Eigen::Vector3f(0.3f, 0.5f, 1.0f), 0.25f);  // world frame
    EXPECT_NEAR(red_at_centre(front_view), 229, 8);
    // Seen from behind, the light comes from behind the sphere: ambient only, 0.25 * 255.
    EXPECT_NEAR(red_at_centre(back_view), 64, 2);
}

// A cloud without the Gaussian attributes draws as points; asking for gaussianSplat on it
// says what is missing; gaussianSplat is no mesh shader.
TEST_F(FilamentTest, AddGeometryChecksTheShaderAgainstTheGeometry) {
    rendering::FilamentScene& scene = MakeScene("placeholder");
    scene.AddGeometry("points", MakePointPatch());
    EXPECT_EQ(scene.GetMaterial("points").shader, rendering::kShaderDefaultUnlit);
    EXPECT_TRUE(scene.HasNonGaussianVisibleGeometry());
    EXPECT_FALSE(scene.HasVisibleGaussianSplats());
    MaterialRecord splat;
    splat.shader = rendering::kShaderGaussianSplat;
    try {
        scene.AddGeometry("not splats", MakePointPatch(), splat);
        ADD_FAILURE() << "no error for a gaussianSplat cloud without Gaussian attributes";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("Gaussian attributes"), std::string::npos) << e.what();
    }
    EXPECT_THROW(scene.AddGeometry("mesh", t::geometry::TriangleMesh::CreateSphere(1.0, 8), splat),
                 core::Open3DError);
    MaterialRecord unknown;
    unknown.shader = "defaultLitTransparency";
    EXPECT_THROW(scene.AddGeometry("other", MakePointPatch(), unknown), core::Open3DError);
    EXPECT_FALSE(scene.HasGeometry("not splats"));
    EXPECT_FALSE(scene.HasGeometry("mesh"));
}

}  // namespace
}  // namespace tests
}  // namespace open3d
