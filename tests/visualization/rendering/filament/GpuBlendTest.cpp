// The offscreen hand-over on the GPU (zero-copy targets): gaussian_blend_over.comp blends the
// splat colour over the mesh colour Filament drew into Vulkan memory. Its 8-bit picture must
// be the host blend's (FilamentRenderer's BlendOver, the host-copy path's formula) of the
// same two images, read back separately: the RGBA16F splat colour through the composite's
// readback and the RGBA8 mesh colour from GL.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "visualization/rendering/filament/FilamentTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using rendering::FrameRequest;
using rendering::FrameResult;
using rendering::SplatSharing;

TEST_F(FilamentTest, GpuBlendOverTheMeshColourIsTheHostBlend) {
    const camera::PinholeCamera camera = MakeFilamentTestCamera(64, 48);
    rendering::FilamentScene& scene = MakeScene();
    // Half-transparent splats in front of and behind the sphere: every case of the blend.
    AddSplatsAroundRedSphere(scene);
    // A yellow box in the upper half (y < 0 is up) and nothing mirrored below it, so a mesh
    // colour read with its rows the wrong way up would not match.
    t::geometry::TriangleMesh box = t::geometry::TriangleMesh::CreateBox(0.6, 0.3, 0.2);
    box.Translate(Eigen::Vector3d(-1.0, -0.9, 2.5));
    rendering::MaterialRecord yellow;
    yellow.base_color = Eigen::Vector4f(1, 1, 0, 1);
    scene.AddGeometry("box", box, yellow);
    rendering::FilamentView& view = MakeView(camera, SplatSharing::kZeroCopy);
    FrameRequest request;
    request.read_color = true;
    const FrameResult frame = renderer_->Draw(scene, view, request);
    ASSERT_TRUE(frame.splats_drawn && frame.scene_depth_used);
    rendering::SplatTargets& targets = *view.GetSplatTargets();
    ASSERT_TRUE(targets.IsZeroCopy());
    ASSERT_EQ(frame.color.GetChannels(), 4);

    // The same frame's two inputs: the splat colour again (the geometry stage is kept), and
    // the mesh colour as GL holds it (row 0 at the bottom).
    rendering::SplatCompositeRequest again;
    again.use_scene_depth = true;
    again.scene_near = static_cast<float>(view.GetMeshNearPlane());
    again.read_color = true;
    rendering::SplatFrame splats;
    targets.Composite(scene.GetBackend(), again, splats);
    const int64_t w = camera.width, h = camera.height;
    std::vector<uint8_t> mesh_gl(size_t(w) * h * 4);
    engine_->MakeContextCurrent();
    const rendering::GlFunctions& gl = engine_->GetGl();
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.GetTextureImage(targets.GetMeshColorGlName(), 0, GL_RGBA, GL_UNSIGNED_BYTE,
                       static_cast<GLsizei>(mesh_gl.size()), mesh_gl.data());
    gl.CheckError("reading the mesh colour");

    const float* s = splats.color.Data<float>();
    const uint8_t* gpu = frame.color.Data<uint8_t>();
    int differ = 0, max_diff = 0, blended = 0;
    for (int64_t v = 0; v < h; ++v) {
        for (int64_t u = 0; u < w; ++u) {
            const size_t i = size_t(v * w + u) * 4;
            const size_t m = size_t((h - 1 - v) * w + u) * 4;
            if (s[i + 3] > 0.0f && s[i + 3] < 1.0f && mesh_gl[m] > 0) ++blended;
            for (int c = 0; c < 4; ++c) {
                const float want_f = s[i + c] + (1.0f - s[i + 3]) * (mesh_gl[m + c] / 255.0f);
                const int want = int(std::lround(std::clamp(want_f, 0.0f, 1.0f) * 255.0f));
                const int d = std::abs(want - int(gpu[i + c]));
                max_diff = std::max(max_diff, d);
                differ += d != 0;
            }
        }
    }
    // Splats partly covering the red sphere: the blend is exercised, not just copied.
    EXPECT_GT(blended, 20);
    // The GPU rounds as lround does; the division m / 255 may be a few ulps off on a GPU
    // (GLSL's precision), which moves a value across a rounding boundary very rarely: on
    // llvmpipe every channel of every pixel agrees.
    EXPECT_LE(max_diff, 1);
    EXPECT_LE(differ, int(w * h * 4 / 1000)) << differ << " channels differ";
}

}  // namespace
}  // namespace tests
}  // namespace open3d
