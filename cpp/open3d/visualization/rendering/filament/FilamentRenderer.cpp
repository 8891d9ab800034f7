#include "open3d/visualization/rendering/filament/FilamentRenderer.h"

#include <backend/PixelBufferDescriptor.h>
#include <filament/Engine.h>
#include <filament/RenderTarget.h>
#include <filament/Renderer.h>
#include <filament/View.h>
#include <filament/Viewport.h>

#include <chrono>
#include <cmath>
#include <cstring>

#include "open3d/core/Exception.h"
#include "open3d/core/Timer.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/filament/FilamentMaterials.h"
#include "open3d/visualization/rendering/filament/FilamentScene.h"
#include "open3d/visualization/rendering/filament/FilamentView.h"

namespace open3d {
namespace visualization {
namespace rendering {

namespace {

using Clock = std::chrono::steady_clock;

// Host "over" of the premultiplied splat colour (float, top row first) on the mesh
// colour (RGBA8, top row first); out = round(255 * (s + (1 - s_a) * m)).
t::geometry::Image BlendOver(const t::geometry::Image* splats, const std::vector<uint8_t>& mesh,
                             int64_t h, int64_t w) {
    t::geometry::Image out(h, w, 4, core::Dtype::UInt8);
    uint8_t* o = out.Data<uint8_t>();
    const float* s = splats ? splats->Data<float>() : nullptr;
    for (int64_t i = 0; i < h * w * 4; i += 4) {
        const float transmit = s ? 1.0f - s[i + 3] : 1.0f;
        for (int c = 0; c < 4; ++c) {
            const float v = (s ? s[i + c] : 0.0f) + transmit * (mesh[i + c] / 255.0f);
            o[i + c] = static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
        }
    }
    return out;
}

}  // namespace

FilamentRenderer::FilamentRenderer(FilamentEngine& engine)
    : engine_(engine),
      materials_(std::make_unique<FilamentMaterials>(engine.GetEngine())),
      renderer_(engine.GetEngine().createRenderer()) {}

FilamentRenderer::~FilamentRenderer() {
    engine_.GetEngine().destroy(renderer_);
    materials_.reset();
}

FrameResult FilamentRenderer::Draw(FilamentScene& scene, FilamentView& view,
                                   const FrameRequest& request, filament::SwapChain* swap_chain) {
    const Clock::time_point start = Clock::now();
    filament::Engine& engine = engine_.GetEngine();
    FrameResult result;
    // The previous frame's GL work on the shared images is done before Vulkan reuses them.
    engine.flushAndWait();

    Clock::time_point t = Clock::now();
    scene.PrepareSplats();
    view.PrepareTargets(scene);
    const camera::PinholeCamera& camera = view.GetCamera();
    const int64_t w = camera.width, h = camera.height;
    result.splats_drawn = scene.HasVisibleGaussianSplats();
    result.scene_depth_used = result.splats_drawn && scene.HasNonGaussianVisibleGeometry();
    if (result.splats_drawn) {
        RenderConfig config = request.splat_config;
        config.background = Eigen::Vector3d::Zero();             // the overlay stays premultiplied
        scene.GetBackend().RenderGeometryStage(camera, config);  // submitted, not waited for
    }
    result.times.geometry_stage_ms = core::MillisecondsSince(t);

    t = Clock::now();
    filament::Renderer::ClearOptions clear;
    const Eigen::Vector4f& bg = view.GetBackground();
    clear.clearColor = {bg[0], bg[1], bg[2], bg[3]};
    clear.clear = true;
    clear.discard = true;
    renderer_->setClearOptions(clear);
    renderer_->renderStandaloneView(view.GetMeshView());
    std::vector<uint8_t> mesh_rgba;
    if (request.read_color) {
        // Filament writes straight into this buffer; it is complete after flushAndWait.
        mesh_rgba.resize(size_t(w) * h * 4);
        renderer_->readPixels(
            view.GetMeshTarget(), 0, 0, uint32_t(w), uint32_t(h),
            filament::backend::PixelBufferDescriptor(mesh_rgba.data(), mesh_rgba.size(),
                                                     filament::backend::PixelDataFormat::RGBA,
                                                     filament::backend::PixelDataType::UBYTE));
    }
    engine.flushAndWait();
    result.times.filament_ms = core::MillisecondsSince(t);

    t = Clock::now();
    SplatFrame splats;
    SplatTargets& targets = *view.GetSplatTargets();
    if (result.splats_drawn) {
        SplatCompositeRequest composite;
        composite.use_scene_depth = result.scene_depth_used;
        composite.scene_near = static_cast<float>(view.GetMeshNearPlane());
        composite.read_color = request.read_color;
        composite.read_depth = request.read_depth;
        composite.depth_near = request.depth_near;
        composite.depth_far = request.depth_far;
        targets.Composite(scene.GetBackend(), composite, splats);
        result.splat_stats = splats.stats;
    } else if (request.read_depth) {
        targets.ReadMeshDepth(static_cast<float>(view.GetMeshNearPlane()), request.depth_near,
                              request.depth_far, splats);
    }
    result.linear_depth = std::move(splats.linear_depth);
    result.normalized_depth = std::move(splats.normalized_depth);
    result.times.composite_stage_ms = core::MillisecondsSince(t);

    view.SetOverlayVisible(result.splats_drawn);
    if (swap_chain != nullptr) {
        t = Clock::now();
        // A frame Filament wants to skip is drawn anyway: the caller asked for this one.
        renderer_->beginFrame(swap_chain);
        renderer_->render(view.GetComposeView());
        for (filament::View* overlay : request.overlay_views) renderer_->render(overlay);
        std::vector<uint8_t> screen;
        if (request.read_screen) {
            screen.resize(size_t(w) * h * 4);
            renderer_->readPixels(
                0, 0, uint32_t(w), uint32_t(h),
                filament::backend::PixelBufferDescriptor(screen.data(), screen.size(),
                                                         filament::backend::PixelDataFormat::RGBA,
                                                         filament::backend::PixelDataType::UBYTE));
        }
        renderer_->endFrame();
        if (request.read_screen) {
            engine.flushAndWait();
            result.screen = t::geometry::Image(h, w, 4, core::Dtype::UInt8);
            std::memcpy(result.screen.Data<uint8_t>(), screen.data(), screen.size());
        }
        result.times.compose_ms = core::MillisecondsSince(t);
    }
    if (request.read_color) {
        t = Clock::now();
        result.color = BlendOver(result.splats_drawn ? &splats.color : nullptr, mesh_rgba, h, w);
        result.times.readback_ms = core::MillisecondsSince(t);
    }
    result.times.total_ms = core::MillisecondsSince(start);
    return result;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
