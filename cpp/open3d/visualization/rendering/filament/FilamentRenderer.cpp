#include "open3d/visualization/rendering/filament/FilamentRenderer.h"

#include <backend/PixelBufferDescriptor.h>
#include <filament/Engine.h>
#include <filament/RenderTarget.h>
#include <filament/Renderer.h>
#include <filament/View.h>
#include <filament/Viewport.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/core/Timer.h"
#include "open3d/core/WaitCallback.h"
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
// Rows in parallel: at 1080p and above the blend is most of an offscreen frame's host time.
t::geometry::Image BlendOver(const t::geometry::Image* splats, const std::vector<uint8_t>& mesh,
                             int64_t h, int64_t w) {
    t::geometry::Image out(h, w, 4, core::Dtype::UInt8);
    uint8_t* o = out.Data<uint8_t>();
    const float* s = splats ? splats->Data<float>() : nullptr;
    core::ParallelForRange(
        h,
        [&](int64_t row_begin, int64_t row_end) {
            for (int64_t i = row_begin * w * 4; i < row_end * w * 4; i += 4) {
                const float transmit = s ? 1.0f - s[i + 3] : 1.0f;
                for (int c = 0; c < 4; ++c) {
                    const float v = (s ? s[i + c] : 0.0f) + transmit * (mesh[i + c] / 255.0f);
                    o[i + c] =
                        static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
                }
            }
        },
        64);
    return out;
}

// The key a view's state has in its scene's GaussianSplatRenderer.
uint64_t ViewKey(const FilamentView& view) { return reinterpret_cast<uintptr_t>(&view); }

}  // namespace

FilamentRenderer::FilamentRenderer(FilamentEngine& engine)
    : engine_(engine),
      materials_(std::make_unique<FilamentMaterials>(engine.GetEngine())),
      renderer_(engine.GetEngine().createRenderer()) {}

FilamentRenderer::~FilamentRenderer() {
    engine_.GetEngine().destroy(renderer_);
    materials_.reset();
}

void FilamentRenderer::AddView(FilamentScene& scene, FilamentView& view) {
    if (frame_begun_) core::ThrowError("FilamentRenderer::AddView: not inside a frame");
    if (ViewEntry* entry = FindView(view)) {
        entry->scene = &scene;
        return;
    }
    ViewEntry entry;
    entry.scene = &scene;
    entry.view = &view;
    views_.push_back(entry);
}

void FilamentRenderer::RemoveView(const FilamentView& view) {
    if (frame_begun_) core::ThrowError("FilamentRenderer::RemoveView: not inside a frame");
    // The scene's splat renderer forgets the view too: its key (the address) may be reused.
    for (const ViewEntry& e : views_) {
        if (e.view == &view) e.scene->GetSplatRenderer().ReleaseView(ViewKey(view));
    }
    std::erase_if(views_, [&](const ViewEntry& e) { return e.view == &view; });
}

FilamentRenderer::ViewEntry* FilamentRenderer::FindView(const FilamentView& view) {
    for (ViewEntry& entry : views_) {
        if (entry.view == &view) return &entry;
    }
    if (temporary_.view == &view) return &temporary_;
    return nullptr;
}

void FilamentRenderer::StartFrame(filament::SwapChain* swap_chain) {
    if (frame_begun_) core::ThrowError("FilamentRenderer::BeginFrame: the frame is begun");
    frame_begun_ = true;
    swap_chain_ = swap_chain;
    drawn_.clear();
    // No wait for the previous frame's GL work: the geometry stages submitted next touch no
    // shared image, and Vulkan writes one only in a view's composite, after Draw's
    // flushAndWait, which the previous frame's compose views precede in Filament's stream.
    // Targets replaced for a new size flush before they free their images (~SplatTargets).
    Report(FrameEvent::kBeginFrame, nullptr);
}

void FilamentRenderer::SubmitGeometryStage(ViewEntry& entry) {
    const Clock::time_point t = Clock::now();
    FilamentScene& scene = *entry.scene;
    FilamentView& view = *entry.view;
    scene.PrepareSplats();
    view.PrepareTargets(scene);
    entry.geometry_submitted = true;
    if (scene.HasVisibleGaussianSplats()) {
        RenderConfig config = view.GetSplatConfig();
        config.background = Eigen::Vector3d::Zero();  // the overlay stays premultiplied
        // Submitted, not waited for: it runs while Filament draws.
        scene.GetSplatRenderer().RenderGeometryStage(ViewKey(view), view.GetCamera(), config);
        Report(FrameEvent::kGeometryStage, &view);
    }
    entry.geometry_stage_ms = core::MillisecondsSince(t);
}

void FilamentRenderer::BeginFrame(filament::SwapChain* swap_chain) {
    StartFrame(swap_chain);
    for (ViewEntry& entry : views_) {
        entry.geometry_submitted = false;
        SubmitGeometryStage(entry);
    }
}

FrameResult FilamentRenderer::Draw(FilamentView& view, const FrameRequest& request) {
    if (!frame_begun_) core::ThrowError("FilamentRenderer::Draw: call BeginFrame first");
    ViewEntry* entry = FindView(view);
    if (entry == nullptr) core::ThrowError("FilamentRenderer::Draw: the view was not added");
    const Clock::time_point start = Clock::now();
    FilamentScene& scene = *entry->scene;
    FrameResult result;
    if (!entry->geometry_submitted) SubmitGeometryStage(*entry);
    result.times.geometry_stage_ms = entry->geometry_stage_ms;

    const camera::PinholeCamera& camera = view.GetCamera();
    const int64_t w = camera.width, h = camera.height;
    result.splats_drawn = !request.skip_splats && scene.HasVisibleGaussianSplats();
    result.scene_depth_used = result.splats_drawn && scene.HasNonGaussianVisibleGeometry();

    Clock::time_point t = Clock::now();
    scene.PrepareLighting(camera);
    filament::Renderer::ClearOptions clear;
    const Eigen::Vector4f& bg = view.GetBackground();
    clear.clearColor = {bg[0], bg[1], bg[2], bg[3]};
    clear.clear = true;
    clear.discard = true;
    renderer_->setClearOptions(clear);
    renderer_->renderStandaloneView(view.GetMeshView());
    // Zero-copy: the splats are blended over the mesh colour on the GPU, which reads
    // Filament's colour attachment itself; otherwise the host reads it and blends.
    SplatTargets& targets = *view.GetSplatTargets();
    const bool gpu_blend = request.read_color && result.splats_drawn && targets.IsZeroCopy();
    std::vector<uint8_t> mesh_rgba;
    if (request.read_color && !gpu_blend) {
        // Filament writes straight into this buffer; it is complete after flushAndWait.
        mesh_rgba.resize(size_t(w) * h * 4);
        renderer_->readPixels(
            view.GetMeshTarget(), 0, 0, uint32_t(w), uint32_t(h),
            filament::backend::PixelBufferDescriptor(mesh_rgba.data(), mesh_rgba.size(),
                                                     filament::backend::PixelDataFormat::RGBA,
                                                     filament::backend::PixelDataType::UBYTE));
    }
    // Zero-copy on EGL, Vulkan waits for GL's semaphore on the GPU; otherwise the host waits
    // for Filament's GL work. A frame that may be cancelled waits on the host: a signal no
    // composite waits for would be left pending.
    const bool signalled = result.splats_drawn && !request.cancelled && targets.SignalMeshDrawn();
    if (!signalled) engine_.FlushAndWait();
    result.times.filament_ms = core::MillisecondsSince(t);
    Report(FrameEvent::kFilamentDraw, &view);
    if (request.cancelled) {
        // The geometry stage is waited for here, in slices with the thread's wait callback
        // between them, so that a close asked for while it runs (seconds for a large scene
        // on a software device) stops the frame before the composite is submitted. A
        // cancelled geometry stage stays submitted; its next user waits for its fence.
        bool cancel = request.cancelled();
        while (!cancel && result.splats_drawn &&
               !scene.GetBackend().WaitGeometryStage(core::kWaitCallbackPeriodMs)) {
            core::CallWaitCallback();
            cancel = request.cancelled();
        }
        if (cancel) {
            result.cancelled = true;
            result.times.total_ms = result.times.geometry_stage_ms + core::MillisecondsSince(start);
            return result;
        }
    }

    t = Clock::now();
    SplatFrame splats;
    if (result.splats_drawn) {
        SplatCompositeRequest composite;
        composite.use_scene_depth = result.scene_depth_used;
        composite.scene_near = static_cast<float>(view.GetMeshNearPlane());
        composite.read_color = request.read_color && !gpu_blend;
        composite.blend_over_mesh = gpu_blend;
        composite.read_depth = request.read_depth;
        composite.depth_near = request.depth_near;
        composite.depth_far = request.depth_far;
        composite.presented = swap_chain_ != nullptr;
        // Another view of the same scene may have replaced this view's sorted entries.
        scene.GetSplatRenderer().EnsureGeometryStage(ViewKey(view));
        targets.Composite(scene.GetBackend(), composite, splats);
        result.splat_stats = splats.stats;
        Report(FrameEvent::kComposite, &view);
    } else if (request.read_depth) {
        targets.ReadMeshDepth(static_cast<float>(view.GetMeshNearPlane()), request.depth_near,
                              request.depth_far, splats);
    }
    result.linear_depth = std::move(splats.linear_depth);
    result.normalized_depth = std::move(splats.normalized_depth);
    result.times.composite_stage_ms = core::MillisecondsSince(t);

    view.SetOverlayVisible(result.splats_drawn);
    if (gpu_blend) {
        result.color = std::move(splats.blended);
    } else if (request.read_color) {
        t = Clock::now();
        result.color = BlendOver(result.splats_drawn ? &splats.color : nullptr, mesh_rgba, h, w);
        result.times.readback_ms = core::MillisecondsSince(t);
    }
    entry->request = request;
    drawn_.push_back(entry);
    result.times.total_ms = result.times.geometry_stage_ms + core::MillisecondsSince(start);
    return result;
}

t::geometry::Image FilamentRenderer::EndFrame() {
    if (!frame_begun_) core::ThrowError("FilamentRenderer::EndFrame: call BeginFrame first");
    frame_begun_ = false;
    t::geometry::Image screen_image;
    if (swap_chain_ != nullptr && !drawn_.empty()) {
        // GL waits on the GPU for composites the host did not wait for (SplatTargets).
        for (ViewEntry* entry : drawn_) {
            SplatTargets* targets = entry->view->GetSplatTargets();
            if (targets != nullptr) targets->WaitSplatsDrawn();
        }
        // A frame Filament wants to skip is drawn anyway: the caller asked for this one.
        renderer_->beginFrame(swap_chain_);
        std::vector<uint8_t> screen;
        int64_t w = 0, h = 0;
        for (ViewEntry* entry : drawn_) {
            renderer_->render(entry->view->GetComposeView());
            for (filament::View* overlay : entry->request.overlay_views) renderer_->render(overlay);
            Report(FrameEvent::kOverlay, entry->view);
            if (entry->request.read_screen) {
                w = entry->view->GetPresentWidth();
                h = entry->view->GetPresentHeight();
            }
        }
        if (w > 0) {
            screen.resize(size_t(w) * h * 4);
            renderer_->readPixels(
                0, 0, uint32_t(w), uint32_t(h),
                filament::backend::PixelBufferDescriptor(screen.data(), screen.size(),
                                                         filament::backend::PixelDataFormat::RGBA,
                                                         filament::backend::PixelDataType::UBYTE));
        }
        renderer_->endFrame();
        if (w > 0) {
            engine_.FlushAndWait();
            screen_image = t::geometry::Image(h, w, 4, core::Dtype::UInt8);
            std::memcpy(screen_image.Data<uint8_t>(), screen.data(), screen.size());
        }
    }
    for (ViewEntry* entry : drawn_) entry->request = FrameRequest{};
    drawn_.clear();
    swap_chain_ = nullptr;
    Report(FrameEvent::kEndFrame, nullptr);
    return screen_image;
}

FrameResult FilamentRenderer::Draw(FilamentScene& scene, FilamentView& view,
                                   const FrameRequest& request, filament::SwapChain* swap_chain) {
    const Clock::time_point start = Clock::now();
    ViewEntry* entry = FindView(view);
    if (entry == nullptr || entry == &temporary_) {
        temporary_ = ViewEntry{};
        temporary_.scene = &scene;
        temporary_.view = &view;
        entry = &temporary_;
    }
    entry->scene = &scene;
    // Only this view's geometry stage: a one-view frame.
    StartFrame(swap_chain);
    entry->geometry_submitted = false;
    FrameResult result;
    try {
        SubmitGeometryStage(*entry);
        result = Draw(view, request);
    } catch (...) {
        frame_begun_ = false;
        drawn_.clear();
        if (entry == &temporary_) scene.GetSplatRenderer().ReleaseView(ViewKey(view));
        temporary_ = ViewEntry{};
        throw;
    }
    const Clock::time_point t = Clock::now();
    result.screen = EndFrame();
    if (swap_chain != nullptr) result.times.compose_ms = core::MillisecondsSince(t);
    // A view drawn only this way is forgotten with its frame.
    if (entry == &temporary_) scene.GetSplatRenderer().ReleaseView(ViewKey(view));
    temporary_ = ViewEntry{};
    result.times.total_ms = core::MillisecondsSince(start);
    return result;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
