#include "FilamentRender.h"

#include <chrono>
#include <cstdio>
#include <utility>

#include "GlGpuTimeline.h"
#include "open3d/core/Timer.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/filament/Open3DScene.h"

namespace gs_render {

namespace rendering = open3d::visualization::rendering;
using namespace open3d;

namespace {

// The square through the sphere's lower half: normal = the camera's up (OpenCV: -y of the camera
// frame, in the world), one side along the camera's right axis flattened onto the plane.
t::geometry::TriangleMesh MakePlane(const camera::PinholeCamera& camera,
                                    const FilamentRenderOptions& options) {
    const Eigen::Matrix3d to_world = camera.world_to_camera.topLeftCorner<3, 3>().transpose();
    const Eigen::Vector3d up = -(to_world * Eigen::Vector3d::UnitY()).normalized();
    Eigen::Vector3d right = to_world * Eigen::Vector3d::UnitX();
    right = (right - right.dot(up) * up).normalized();
    const Eigen::Vector3d forward = up.cross(right);
    const double r = options.sphere_radius, half = 3.0 * r;
    const Eigen::Vector3d centre = options.sphere_center - 0.5 * r * up;
    std::vector<float> positions;
    for (const auto& [a, b] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        const Eigen::Vector3d p = centre + half * (a * right + b * forward);
        positions.insert(positions.end(), {float(p.x()), float(p.y()), float(p.z())});
    }
    // Two-sided when lit (defaultLit), so the winding only has to be consistent.
    return t::geometry::TriangleMesh(core::Tensor::FromVector(positions, {4, 3}),
                                     {Eigen::Vector3i(0, 1, 2), Eigen::Vector3i(0, 2, 3)});
}

rendering::MaterialRecord MakeGrey() {
    rendering::MaterialRecord grey;
    grey.shader = rendering::kShaderDefaultLit;
    grey.base_color = Eigen::Vector4f(0.6f, 0.6f, 0.6f, 1.0f);
    return grey;
}

// The viewer's frame without a window: BeginFrame, Draw and EndFrame onto a headless swap
// chain of the image's size, nothing read back, so each frame waits only where the renderer
// itself does. The wall time per frame over frames - 1 frames after one warm-up frame, with
// the GL work of the last one finished, is what a window would show at most.
void PresentFrames(rendering::FilamentEngine& engine, rendering::FilamentRenderer& renderer,
                   rendering::Open3DScene& scene, int frames) {
    const camera::PinholeCamera& camera = scene.GetCamera();
    const rendering::HeadlessSwapChain swap_chain(engine, camera.width, camera.height);
    scene.GetView().SetPresentSize(camera.width, camera.height);
    renderer.AddView(scene.GetScene(), scene.GetView());
    rendering::FrameTimes sum;
    double record_ms = 0.0, wait_ms = 0.0;  // the splat stages' host recording and fence waits
    std::chrono::steady_clock::time_point start;
    // GL timestamps at three places of each frame (the views of one frame are one here).
    GlGpuTimeline timeline(engine);
    int frame = 0;
    renderer.SetFrameEventListener(
        [&](rendering::FrameEvent event, const rendering::FilamentView*) {
            if (event == rendering::FrameEvent::kBeginFrame) {
                timeline.Mark(frame, GlGpuTimeline::kFrameBegin);
            } else if (event == rendering::FrameEvent::kFilamentDraw) {
                timeline.Mark(frame, GlGpuTimeline::kMeshDone);
            } else if (event == rendering::FrameEvent::kOverlay) {
                timeline.Mark(frame, GlGpuTimeline::kComposeDone);
            }
        });
    for (int i = 0; i < frames; ++i) {
        frame = i;
        if (i == 1) {
            engine.FlushAndWait();
            start = std::chrono::steady_clock::now();
        }
        renderer.BeginFrame(swap_chain.Get());
        rendering::FrameResult result = renderer.Draw(scene.GetView(), rendering::FrameRequest{});
        const auto compose = std::chrono::steady_clock::now();
        renderer.EndFrame();
        if (i == 0) continue;
        result.times.compose_ms = core::MillisecondsSince(compose);
        sum.geometry_stage_ms += result.times.geometry_stage_ms;
        sum.filament_ms += result.times.filament_ms;
        sum.composite_stage_ms += result.times.composite_stage_ms;
        sum.compose_ms += result.times.compose_ms;
        record_ms += result.splat_stats.host_record_ms;
        wait_ms += result.splat_stats.host_wait_ms;
    }
    engine.FlushAndWait();
    const int n = frames - 1;
    const double wall_ms = core::MillisecondsSince(start) / n;
    std::printf(
        "presented frames (headless swap chain, no readback, mean of %d): %.3f ms wall per "
        "frame (%.0f frames/s) = geometry stage %.3f + Filament %.3f + composite stage %.3f + "
        "compose %.3f, the rest waits; the splat stages record for %.3f and wait for fences "
        "%.3f\n",
        n, wall_ms, 1000.0 / wall_ms, sum.geometry_stage_ms / n, sum.filament_ms / n,
        sum.composite_stage_ms / n, sum.compose_ms / n, record_ms / n, wait_ms / n);
    renderer.SetFrameEventListener(nullptr);
    std::printf("%s\n", timeline.Describe(1).c_str());
    renderer.RemoveView(scene.GetView());
    scene.GetView().SetPresentSize(0, 0);
}

}  // namespace

FilamentImages RenderWithFilament(const t::geometry::PointCloud& cloud,
                                  const camera::PinholeCamera& camera,
                                  const rendering::RenderConfig& config,
                                  const FilamentRenderOptions& options) {
    rendering::FilamentEngine engine;
    rendering::FilamentRenderer renderer(engine);
    rendering::Open3DSceneOptions scene_options;
    scene_options.backend = options.backend;
    rendering::Open3DScene scene(renderer, scene_options);
    if (options.splats) scene.AddGeometry("splats", cloud);
    if (options.sphere) {
        t::geometry::TriangleMesh sphere =
            t::geometry::TriangleMesh::CreateSphere(options.sphere_radius, 40);
        sphere.Translate(options.sphere_center);
        rendering::MaterialRecord red;
        red.shader = rendering::kShaderDefaultLit;
        red.base_color = Eigen::Vector4f(1, 0, 0, 1);
        scene.AddGeometry("sphere", sphere, red);
    }
    if (options.plane) scene.AddGeometry("plane", MakePlane(camera, options), MakeGrey());
    const Eigen::Vector3f bg = options.background.cast<float>();
    scene.SetBackground(Eigen::Vector4f(bg.x(), bg.y(), bg.z(), 1.0f));
    scene.SetupCamera(camera);
    scene.GetSplatConfig() = config;
    // Every frame runs the whole pipeline (geometry stage too), so the times are comparable.
    scene.GetSplatConfig().reuse_geometry = options.frames <= 1;

    t::geometry::Image image;
    rendering::FrameTimes sum;
    for (int i = 0; i < options.frames; ++i) {
        image = scene.RenderToImage();
        const rendering::FrameTimes& t = scene.GetLastFrame().times;
        if (i == 0 && options.frames > 1) continue;  // shader compilation, first uploads
        sum.geometry_stage_ms += t.geometry_stage_ms;
        sum.filament_ms += t.filament_ms;
        sum.composite_stage_ms += t.composite_stage_ms;
        sum.readback_ms += t.readback_ms;
        sum.total_ms += t.total_ms;
    }
    const int n = options.frames > 1 ? options.frames - 1 : 1;
    const rendering::FrameResult& last = scene.GetLastFrame();
    std::printf(
        "filament render: %dx%d, splats %s%s, %lld visible, %lld tile entries, splat images "
        "%s\n",
        camera.width, camera.height, last.splats_drawn ? "drawn" : "not drawn",
        last.scene_depth_used ? " (depth-tested against the sphere)" : "",
        static_cast<long long>(last.splat_stats.num_visible),
        static_cast<long long>(last.splat_stats.num_tile_entries),
        scene.GetView().GetSplatTargets() && scene.GetView().GetSplatTargets()->IsZeroCopy()
            ? "zero-copy"
            : "host copies");
    std::printf(
        "frame time (mean of %d): %.2f ms = geometry stage %.2f + Filament %.2f + composite stage "
        "%.2f + "
        "readback/blend %.2f (GPU: project %.3f, sort %.3f, composite %.3f ms)\n",
        n, sum.total_ms / n, sum.geometry_stage_ms / n, sum.filament_ms / n,
        sum.composite_stage_ms / n, sum.readback_ms / n, last.splat_stats.gpu_project_ms,
        last.splat_stats.gpu_sort_ms, last.splat_stats.gpu_composite_ms);
    if (options.frames > 1) PresentFrames(engine, renderer, scene, options.frames);
    FilamentImages images;
    images.color = std::move(image);
    if (options.depth) images.depth = scene.RenderToDepthImage();
    return images;
}

}  // namespace gs_render
