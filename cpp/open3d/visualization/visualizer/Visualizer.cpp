#include "open3d/visualization/visualizer/Visualizer.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/Timer.h"
#include "open3d/core/WaitCallback.h"
#include "open3d/t/io/ImageIO.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/filament/FilamentRenderer.h"
#include "open3d/visualization/visualizer/filament/ImGuiOverlay.h"
#include "open3d/visualization/visualizer/filament/VisualizerWindow.h"

namespace open3d {
namespace visualization {

namespace {

double NowSeconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

// UInt8 [H, W, 4] -> [H, W, 3].
t::geometry::Image DropAlpha(const t::geometry::Image& rgba) {
    t::geometry::Image rgb(rgba.GetRows(), rgba.GetCols(), 3, core::Dtype::UInt8);
    const uint8_t* src = rgba.Data<uint8_t>();
    uint8_t* dst = rgb.Data<uint8_t>();
    for (int64_t i = 0; i < rgba.NumPixels(); ++i) std::memcpy(dst + 3 * i, src + 4 * i, 3);
    return rgb;
}

}  // namespace

Visualizer::Visualizer(const VisualizerOptions& options) {
    owned_engine_ = std::make_unique<rendering::FilamentEngine>(rendering::GlPlatform::kGlx);
    owned_renderer_ = std::make_unique<rendering::FilamentRenderer>(*owned_engine_);
    renderer_ = owned_renderer_.get();
    Init(options);
}

Visualizer::Visualizer(rendering::FilamentRenderer& renderer, const VisualizerOptions& options)
    : renderer_(&renderer) {
    Init(options);
}

void Visualizer::Init(const VisualizerOptions& options) {
    view_control_.SetUp(options.up);
    view_control_.SetVerticalFov(options.vertical_fov_deg);
    view_control_.SetHomePitch(options.home_pitch_deg);
    view_control_.SetViewSize(options.width, options.height);
    show_settings_ = options.show_settings;
    screenshot_dir_ = options.screenshot_dir.empty() ? "." : options.screenshot_dir;
    interactive_frame_ms_ = options.interactive_frame_ms;
    SetLodTargetMs(options.lod_target_ms);
    first_frame_notice_splats_ = options.first_frame_notice_splats;
    rendering::FilamentEngine& engine = renderer_->GetEngine();
    window_ = std::make_unique<VisualizerWindow>(engine, options.title, options.width,
                                                 options.height, this);
    scene_ = std::make_unique<rendering::Open3DScene>(*renderer_, options.scene);
    overlay_ = std::make_unique<ImGuiOverlay>(engine);
    int w = 0, h = 0;
    window_->GetFramebufferSize(&w, &h);
    OnFramebufferSize(w, h);
}

Visualizer::~Visualizer() {
    // Filament objects first (the overlay's view, the scene's views and targets), then the
    // swap chain and the window, then the engine when it is ours.
    overlay_.reset();
    scene_.reset();
    window_.reset();
    owned_renderer_.reset();
    owned_engine_.reset();
}

void Visualizer::NoteNewSplats(const t::geometry::PointCloud& cloud) {
    if (cloud.IsGaussianSplat()) new_splats_ += cloud.NumPoints();
}

void Visualizer::AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud) {
    RequireObjectName(name);
    scene_->AddGeometry(name, cloud);
    NoteNewSplats(cloud);
    names_.push_back(name);
    PostRedraw();
}

void Visualizer::AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud,
                             const rendering::MaterialRecord& material) {
    RequireObjectName(name);
    scene_->AddGeometry(name, cloud, material);
    NoteNewSplats(cloud);
    names_.push_back(name);
    PostRedraw();
}

void Visualizer::AddGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh,
                             const rendering::MaterialRecord& material) {
    RequireObjectName(name);
    scene_->AddGeometry(name, mesh, material);
    names_.push_back(name);
    PostRedraw();
}

void Visualizer::UpdateGeometry(const std::string& name, const t::geometry::PointCloud& cloud) {
    scene_->UpdateGeometry(name, cloud);
    NoteNewSplats(cloud);
    PostRedraw();
}

void Visualizer::UpdateGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh) {
    scene_->UpdateGeometry(name, mesh);
    PostRedraw();
}

void Visualizer::StreamSplats(const std::string& path,
                              const rendering::SplatStreamOptions& options) {
    scene_->GetScene().GetSplatRenderer().StreamSplats(path, options);
    PostRedraw();
}

bool Visualizer::StopStreaming() {
    PostRedraw();
    return scene_->GetScene().GetSplatRenderer().StopStreaming();
}

void Visualizer::ShowStream(bool show) {
    scene_->GetScene().GetSplatRenderer().ShowStream(show);
    PostRedraw();
}

bool Visualizer::IsStreamVisible() const {
    return scene_->GetScene().GetSplatRenderer().IsStreamVisible();
}

std::optional<rendering::SplatStreamProgress> Visualizer::GetStreamProgress() const {
    return scene_->GetScene().GetSplatRenderer().GetStreamProgress();
}

bool Visualizer::RemoveGeometry(const std::string& name) {
    const auto it = std::find(names_.begin(), names_.end(), name);
    if (it == names_.end() || !scene_->RemoveGeometry(name)) return false;
    names_.erase(it);
    if (selection_.erase(name) > 0) UpdateSelectionOverlay();
    PostRedraw();
    return true;
}

void Visualizer::ShowGeometry(const std::string& name, bool show) {
    scene_->ShowGeometry(name, show);
    PostRedraw();
}

bool Visualizer::HasGeometry(const std::string& name) const { return scene_->HasGeometry(name); }

bool Visualizer::IsGeometryVisible(const std::string& name) const {
    return scene_->GetScene().IsGeometryVisible(name);
}

void Visualizer::ToggleGeometry(size_t index) {
    if (index >= names_.size()) return;
    ShowGeometry(names_[index], !IsGeometryVisible(names_[index]));
}

void Visualizer::ResetCamera() {
    Eigen::Vector3d lo, hi;
    if (!scene_->GetScene().GetBounds(lo, hi)) {
        lo = Eigen::Vector3d::Constant(-1.0);
        hi = Eigen::Vector3d::Constant(1.0);
    }
    view_control_.FitBounds(lo, hi);
    PostRedraw();
}

void Visualizer::SetCamera(const camera::LookAtCamera& look_at) {
    view_control_.SetLookAt(look_at);
    PostRedraw();
}

void Visualizer::SetCamera(const camera::PinholeCamera& camera) {
    camera.Validate();
    double distance = 1.0;
    Eigen::Vector3d lo, hi;
    if (scene_->GetScene().GetBounds(lo, hi)) {
        const Eigen::Vector3d forward = camera.GetRotation().row(2).transpose();
        distance = (0.5 * (lo + hi) - camera.GetCenter()).dot(forward);
        if (!(distance > 1e-6)) distance = std::max(0.5 * (hi - lo).norm(), 1e-3);
    }
    view_control_.SetLookAt(camera.ToLookAt(distance));
    PostRedraw();
}

void Visualizer::SetBackground(const Eigen::Vector4f& rgba) {
    scene_->SetBackground(rgba);
    PostRedraw();
}

const Eigen::Vector4f& Visualizer::GetBackground() const {
    return scene_->GetView().GetBackground();
}

std::string Visualizer::GetBackendName() const { return scene_->GetScene().GetBackend().GetName(); }

bool Visualizer::PollEvents() {
    VisualizerWindow::PollEvents();
    return !window_->ShouldClose();
}

void Visualizer::Close() { window_->SetShouldClose(true); }

bool Visualizer::BuildOverlay() {
    if (!show_settings_) return true;
    if (overlay_width_ != fb_width_ || overlay_height_ != fb_height_) {
        overlay_->SetSize(fb_width_, fb_height_);
        overlay_width_ = fb_width_;
        overlay_height_ = fb_height_;
    }
    const double dt = last_present_s_ < 0.0 ? 1.0 / 60.0 : NowSeconds() - last_present_s_;
    overlay_->Build(dt, [this] { BuildPanel(); });
    if (!overlay_->HasPendingInput()) return true;
    redraw_frames_ = std::max(redraw_frames_, 1);
    return false;
}

bool Visualizer::DeferDuringFrame(std::function<void()> handler) {
    if (!in_frame_) return false;
    deferred_.push_back(std::move(handler));
    return true;
}

bool Visualizer::IsCameraMoving() const {
    return drag_ == Drag::kRotate || drag_ == Drag::kPan || NowSeconds() - last_motion_s_ < 0.25;
}

void Visualizer::NoteCameraMotion() { last_motion_s_ = NowSeconds(); }

int Visualizer::InteractiveDivisor() const {
    if (interactive_frame_ms_ <= 0.0 || !IsCameraMoving()) return 1;
    // The frame's cost follows its pixel count: half of each side is a quarter of the time.
    const double over = full_frame_ms_ / interactive_frame_ms_;
    return over <= 1.0 ? 1 : over <= 4.0 ? 2 : 4;
}

void Visualizer::SetSplatHierarchy(const std::string& name,
                                   std::shared_ptr<const t::geometry::SplatHierarchy> hierarchy) {
    scene_->GetScene().GetSplatRenderer().SetCloudHierarchy(name, std::move(hierarchy));
    PostRedraw();
}

void Visualizer::SetLodTargetMs(double ms) {
    if (!(std::isfinite(ms) && ms >= 0.0)) {
        core::ThrowError("Visualizer: the level-of-detail target must be >= 0 ms, not {}", ms);
    }
    lod_target_ms_ = ms;
    PostRedraw();
}

rendering::FrameResult Visualizer::DrawToWindow(bool read_screen, int divisor, bool skip_splats) {
    const camera::PinholeCamera camera = view_control_.GetCamera();
    // A hierarchy scene's cut holds the target while the camera moves; still, every leaf.
    scene_->GetSplatConfig().lod_target_ms = IsCameraMoving() ? lod_target_ms_ : 0.0;
    scene_->SetupCamera(divisor > 1 ? camera.Resized(std::max(1, camera.width / divisor),
                                                     std::max(1, camera.height / divisor))
                                    : camera);
    scene_->GetView().SetPresentSize(fb_width_, fb_height_);
    rendering::FrameRequest request;
    request.read_screen = read_screen;
    request.skip_splats = skip_splats;
    if (show_settings_) request.overlay_views.push_back(overlay_->GetView());
    // A close asked for during this frame (Q, Esc, the window's close button) skips its
    // composite and present; one asked for before it does not (a last screenshot at exit).
    const bool closing_before = window_->ShouldClose();
    request.cancelled = [this, closing_before] {
        return !closing_before && window_->ShouldClose();
    };
    rendering::FrameResult result;
    {
        // The frame's GPU waits poll window events; the handlers keep them for after it.
        struct InFrame {
            bool& flag;
            explicit InFrame(bool& f) : flag(f) { flag = true; }
            ~InFrame() { flag = false; }
        } in_frame(in_frame_);
        core::ScopedWaitCallback poll([] { VisualizerWindow::PollEvents(); });
        // The seed's frame: the geometry stage of every view, Filament's draw and the
        // composite, then the compose and overlay views presented.
        renderer_->BeginFrame(window_->GetSwapChain());
        try {
            result = renderer_->Draw(scene_->GetView(), request);
        } catch (...) {
            renderer_->EndFrame();
            throw;
        }
        const auto compose_start = std::chrono::steady_clock::now();
        result.screen = renderer_->EndFrame();
        result.times.compose_ms = core::MillisecondsSince(compose_start);
        result.times.total_ms += result.times.compose_ms;
    }
    if (!result.cancelled && !skip_splats) {
        // What the next frame's resolution is chosen from (InteractiveDivisor).
        last_divisor_ = divisor;
        if (divisor == 1) full_frame_ms_ = result.times.total_ms;
    }
    std::vector<std::function<void()>> events;
    events.swap(deferred_);
    for (const std::function<void()>& event : events) event();
    return result;
}

bool Visualizer::RenderFrame() {
    if (fb_width_ <= 0 || fb_height_ <= 0) {
        last_present_s_ = -1.0;  // the time minimised is not a frame time
        return false;
    }
    if (redraw_frames_ > 0) --redraw_frames_;
    if (new_splats_ > 0 && first_frame_notice_splats_ > 0 &&
        new_splats_ >= first_frame_notice_splats_ && show_settings_) {
        // The notice frame: the panel with the line, no splats, presented at once; the
        // geometry stage it submits runs on while it shows and serves the next frame.
        const std::string status = status_;
        const bool warning = status_warning_;
        status_ = fmt::format("Drawing the first frame of {} splats...", new_splats_);
        status_warning_ = false;
        BuildOverlay();
        DrawToWindow(false, 1, true);
        status_ = status;
        status_warning_ = warning;
    }
    // A screenshot waits until ImGui has seen all input (a click takes two frames), so it
    // shows the state after everything that came before the request.
    const bool settled = BuildOverlay();
    const bool screenshot = settled && screenshot_pending_;
    if (screenshot && new_splats_ > 0) {
        // New splats not yet drawn: the panel would show the last frame's numbers (no
        // splats for a new scene). A plain frame first, then the shot with its numbers.
        last_frame_ = DrawToWindow(false, 1);
        if (last_frame_.cancelled) {
            last_present_s_ = -1.0;
            return true;  // the shot stays pending
        }
        if (last_frame_.splats_drawn) new_splats_ = 0;
        BuildOverlay();
    }
    const int divisor = screenshot ? 1 : InteractiveDivisor();  // screenshots: full size
    last_frame_ = DrawToWindow(screenshot, divisor);
    if (last_frame_.cancelled) {
        last_present_s_ = -1.0;  // nothing was presented
        return true;
    }
    if (last_frame_.splats_drawn) new_splats_ = 0;
    const double now = NowSeconds();
    if (last_present_s_ >= 0.0)
        frame_stats_.Add(1000.0 * (now - last_present_s_), last_frame_.times);
    last_present_s_ = now;
    if (screenshot) WriteScreenshot(DropAlpha(last_frame_.screen));
    return true;
}

std::string Visualizer::NextScreenshotPath() const {
    return (std::filesystem::path(screenshot_dir_) /
            fmt::format("screenshot_{:04d}.png", screenshot_index_))
        .string();
}

void Visualizer::WriteScreenshot(const t::geometry::Image& rgb) {
    const std::string path = NextScreenshotPath();
    screenshot_pending_ = false;
    // Written under another name, then renamed: a watcher never sees half a file. A failure
    // (a folder that cannot be made, a full disk) is a message; the viewer goes on.
    const std::string partial = path + ".part";
    try {
        const std::filesystem::path folder = std::filesystem::path(path).parent_path();
        if (!folder.empty()) std::filesystem::create_directories(folder);
        t::io::WritePNG(partial, rgb);
        std::filesystem::rename(partial, path);
    } catch (const std::exception& e) {
        std::error_code ignored;
        std::filesystem::remove(partial, ignored);
        screenshot_error_ = fmt::format("Screenshot not saved: {}", e.what());
        core::LogWarning("{}", screenshot_error_);
        return;
    }
    screenshot_error_.clear();
    last_screenshot_ = path;
    ++screenshot_index_;
    core::LogInfo("Saved screenshot {}", path);
}

void Visualizer::NoteBackgroundChanges() {
    // A reduced frame while the camera moved is refined once it stops.
    if (last_divisor_ > 1 && !IsCameraMoving()) PostRedraw();
    // Pages that arrived show in the next frame (within the 0.1 s an idle loop sleeps),
    // and so does a new progress line (the last step taken, the stream settled).
    if (scene_->GetScene().GetSplatRenderer().HasStreamNews()) PostRedraw();
    if (const auto progress = GetStreamProgress()) {
        std::string line = rendering::FormatStreamProgress(*progress);
        if (line != stream_line_) {
            stream_line_ = std::move(line);
            PostRedraw();
        }
    }
}

bool Visualizer::IsIdle() {
    NoteBackgroundChanges();
    if (redraw_frames_ > 0 && fb_width_ > 0 && fb_height_ > 0) return false;
    const auto progress = GetStreamProgress();
    return !progress || progress->settled;
}

void Visualizer::Run(const RunOptions& options) {
    const double start = NowSeconds();
    int64_t frames = 0;
    while (PollEvents()) {
        if (options.poll) options.poll();
        const bool idle = IsIdle();
        if (options.until_idle && !options.continuous && idle) break;
        if (fb_width_ <= 0 || fb_height_ <= 0 || !(options.continuous || redraw_frames_ > 0)) {
            // Minimised or idle: sleep until input. The gap is not a frame time.
            last_present_s_ = -1.0;
            VisualizerWindow::WaitEvents(0.1);
        } else {
            if (options.before_frame) options.before_frame();
            RenderFrame();
            ++frames;
            if (options.max_frames > 0 && frames >= options.max_frames) break;
        }
        if (options.max_seconds > 0.0 && NowSeconds() - start >= options.max_seconds) break;
    }
}

t::geometry::Image Visualizer::CaptureScreenImage() {
    if (fb_width_ <= 0 || fb_height_ <= 0) {
        core::ThrowError("CaptureScreenImage: the window is minimised (nothing is drawn)");
    }
    BuildOverlay();
    last_frame_ = DrawToWindow(true, InteractiveDivisor());
    return DropAlpha(last_frame_.screen);
}

std::string Visualizer::RequestScreenshot() {
    screenshot_pending_ = true;
    PostRedraw();
    return NextScreenshotPath();
}

t::geometry::Image Visualizer::RenderToImage(bool with_alpha) {
    scene_->SetupCamera(view_control_.GetCamera());
    t::geometry::Image image = scene_->RenderToImage(with_alpha);
    last_frame_ = scene_->GetLastFrame();
    return image;
}

t::geometry::Image Visualizer::RenderToDepthImage(rendering::DepthFormat format,
                                                  std::optional<float> near,
                                                  std::optional<float> far) {
    scene_->SetupCamera(view_control_.GetCamera());
    t::geometry::Image image = scene_->RenderToDepthImage(format, near, far);
    last_frame_ = scene_->GetLastFrame();
    return image;
}

void Visualizer::SetWindowSize(int width, int height) { window_->SetSize(width, height); }
void Visualizer::Minimize() { window_->Iconify(); }
void Visualizer::Maximize() { window_->Maximize(); }
void Visualizer::Restore() { window_->Restore(); }
uint64_t Visualizer::GetX11WindowId() const { return window_->GetX11WindowId(); }

void Draw(const std::vector<DrawObject>& objects, const VisualizerOptions& options,
          const RunOptions& run) {
    Visualizer vis(options);
    for (const DrawObject& object : objects) {
        if (const auto* stream = std::get_if<StreamedSplats>(&object.geometry)) {
            vis.StreamSplats(stream->path, stream->options);
            continue;
        }
        if (const auto* cloud = std::get_if<t::geometry::PointCloud>(&object.geometry)) {
            if (object.material) {
                vis.AddGeometry(object.name, *cloud, *object.material);
            } else {
                vis.AddGeometry(object.name, *cloud);
            }
        } else {
            vis.AddGeometry(object.name, std::get<t::geometry::TriangleMesh>(object.geometry),
                            object.material.value_or(rendering::MaterialRecord{}));
        }
        if (!object.visible) vis.ShowGeometry(object.name, false);
    }
    vis.ResetCamera();
    vis.Run(run);
}

}  // namespace visualization
}  // namespace open3d
