// The backend interface: factory by name, the placeholder backend, stage order, and the
// built-in default scene.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <string>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"

namespace open3d {
namespace tests {

using namespace visualization::rendering;

TEST(GaussianSplatBackend, FactoryByName) {
    const auto names = GetGaussianSplatBackendNames();
    EXPECT_NE(std::find(names.begin(), names.end(), "cpu"), names.end());
    EXPECT_NE(std::find(names.begin(), names.end(), "placeholder"), names.end());
    EXPECT_EQ(CreateGaussianSplatBackend("cpu")->GetName(), "cpu");
    try {
        CreateGaussianSplatBackend("no-such-backend");
        FAIL() << "expected an error";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("no-such-backend"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("cpu"), std::string::npos);
    }
}

TEST(GaussianSplatBackend, CompositeBeforeGeometryThrows) {
    auto backend = CreateGaussianSplatBackend("cpu");
    backend->SetScene(CreateDefaultGaussianSplatScene());
    RenderOutput out;
    EXPECT_THROW(backend->RenderCompositeStage(out), core::Open3DError);
    EXPECT_THROW(CreateGaussianSplatBackend("cpu")->RenderGeometryStage(GetDefaultSceneCamera(),
                                                                        RenderConfig{}),
                 core::Open3DError);
}

TEST(GaussianSplatBackend, NearPlaneMustBePositiveAndFinite) {
    // A negative near plane would keep splats behind the camera (projected mirrored), NaN
    // would cull everything: both are errors on every registered backend, not images.
    for (const std::string& name : GetGaussianSplatBackendNames()) {
        SCOPED_TRACE(name);
        std::unique_ptr<GaussianSplatBackend> backend;
        try {
            backend = CreateGaussianSplatBackend(name);
        } catch (const core::Open3DError&) {
            continue;  // e.g. "vulkan" without a device; its suite covers it with one
        }
        backend->SetScene(CreateDefaultGaussianSplatScene());
        for (double near : {-1.0, 0.0, std::nan(""), HUGE_VAL}) {
            RenderConfig config;
            config.near_plane = near;
            try {
                backend->RenderGeometryStage(GetDefaultSceneCamera(), config);
                FAIL() << "near_plane " << near << " was accepted";
            } catch (const core::Open3DError& e) {
                EXPECT_NE(std::string(e.what()).find("near_plane"), std::string::npos) << e.what();
            }
        }
        RenderConfig ok;
        ok.near_plane = 1e-3;
        EXPECT_NO_THROW(backend->RenderGeometryStage(GetDefaultSceneCamera(), ok));
    }
}

TEST(GaussianSplatBackend, PlaceholderLogsOnceAndDrawsNothing) {
    int warnings = 0;
    auto previous = core::SetLogSink([&](core::LogLevel level, std::string_view) {
        if (level == core::LogLevel::Warning) ++warnings;
    });
    auto backend = CreateGaussianSplatBackend("placeholder");
    backend->SetScene(CreateDefaultGaussianSplatScene());
    RenderConfig config;
    config.background = {0.25, 0.5, 0.75};
    RenderOutput out;
    for (int i = 0; i < 3; ++i) out = backend->Render(GetDefaultSceneCamera(32, 24), config);
    core::SetLogSink(previous);
    EXPECT_EQ(warnings, 1);
    ASSERT_EQ(out.color.GetRows(), 24);
    ASSERT_EQ(out.color.GetCols(), 32);
    EXPECT_EQ(out.color.At<float>(10, 10, 1), 0.5f);
    EXPECT_EQ(out.color.At<float>(10, 10, 3), 0.0f);
    EXPECT_EQ(out.depth_expected.At<float>(10, 10), 0.0f);
}

TEST(DefaultScene, ExercisesShDegree3AnisotropyAndPartialOpacity) {
    const auto cloud = CreateDefaultGaussianSplatScene();
    EXPECT_EQ(cloud.GaussianSplatGetSHOrder(), 3);
    EXPECT_GT(cloud.NumPoints(), 2000);
    EXPECT_LT(cloud.NumPoints(), 6000);
    const float* scale = cloud.GetPointAttr("scale").Data<float>();
    const float* logit = cloud.GetPointAttr("opacity").Data<float>();
    int anisotropic = 0, partial = 0;
    for (int64_t i = 0; i < cloud.NumPoints(); ++i) {
        const float mx = std::max({scale[3 * i], scale[3 * i + 1], scale[3 * i + 2]});
        const float mn = std::min({scale[3 * i], scale[3 * i + 1], scale[3 * i + 2]});
        anisotropic += mx > 2 * mn;
        const double op = 1 / (1 + std::exp(-logit[i]));
        partial += op < 0.6;
    }
    EXPECT_GT(anisotropic, cloud.NumPoints() / 2);
    EXPECT_GT(partial, 100);

    // View dependence: the sphere's colour changes when the camera orbits.
    auto look_at = GetDefaultSceneLookAt();
    const auto a = cpu::RenderReference(cloud, GetDefaultSceneCamera(64, 48));
    const auto b = cpu::RenderReference(
        cloud, camera::PinholeCamera::FromLookAt(camera::OrbitLookAt(look_at, 90.0), 64, 48));
    // The sphere centre projects near the image centre from any orbit angle.
    double diff = 0;
    for (int c = 0; c < 3; ++c)
        diff += std::abs(a.color.At<float>(20, 32, c) - b.color.At<float>(20, 32, c));
    EXPECT_GT(diff, 0.05);
    // Covered: the sphere fills the middle.
    EXPECT_GT(a.color.At<float>(20, 32, 3), 0.99f);
}

// Its speed is the benchmarks' business (no timed assertion here).
TEST(DefaultScene, RendersAt640x480) {
    const auto cloud = CreateDefaultGaussianSplatScene();
    const auto out = cpu::RenderReference(cloud, GetDefaultSceneCamera(640, 480));
    EXPECT_GT(out.stats.num_visible, 3000);
}

}  // namespace tests
}  // namespace open3d
