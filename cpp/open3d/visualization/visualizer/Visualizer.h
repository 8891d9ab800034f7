// The Open3D-style visualizer (docs/viewer.md): a window showing an Open3DScene of named
// splat clouds and meshes, an orbit camera driven by mouse and keys, a settings panel drawn
// with ImGui over the picture, screenshots, and offscreen renders of the same scene.
//
//   Visualizer vis({.title = "scene", .width = 1280, .height = 720});
//   vis.AddGeometry("splats", cloud);
//   vis.ResetCamera();
//   vis.Run();
//
// Everything runs on the calling thread (the one that made the Filament engine).
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "open3d/camera/CamerasJson.h"
#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/BoundingBox.h"
#include "open3d/t/geometry/Image.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/filament/Open3DScene.h"
#include "open3d/visualization/visualizer/FrameStatistics.h"
#include "open3d/visualization/visualizer/ViewControl.h"
#include "open3d/visualization/visualizer/WindowEventHandler.h"

namespace open3d {
namespace visualization {

namespace rendering {
class FilamentEngine;
class FilamentRenderer;
}  // namespace rendering
class ImGuiOverlay;
class VisualizerWindow;

struct VisualizerOptions {
    std::string title = "Open3D";
    /// Window size in pixels.
    int width = 1280;
    int height = 720;
    /// Splat backend and image sharing (Open3DSceneOptions).
    rendering::Open3DSceneOptions scene;
    /// World up of the orbit camera: -y for 3DGS / COLMAP scenes.
    Eigen::Vector3d up = Eigen::Vector3d(0, -1, 0);
    double vertical_fov_deg = 60.0;
    /// Pitch of ResetCamera's view in degrees (> 0 looks down on the scene).
    double home_pitch_deg = 0.0;
    /// Show the settings panel (key H toggles it).
    bool show_settings = true;
    /// Where SaveScreenshot and the P key write screenshot_NNNN.png.
    std::string screenshot_dir = ".";
    /// While the camera moves, a frame whose last full-resolution time exceeded this many
    /// milliseconds is drawn at 1/2 (up to 4x over) or 1/4 of each side and scaled up; the
    /// full-resolution frame follows when the motion stops. 0: always full resolution.
    double interactive_frame_ms = 100.0;
    /// While the camera moves, a splat cloud given a level-of-detail hierarchy
    /// (SetSplatHierarchy) is drawn through a cut whose budget holds this many milliseconds of
    /// GPU time per frame (RenderConfig::lod_target_ms); when it stops, every leaf: the cloud
    /// exactly. 0: always exact.
    double lod_target_ms = 0.0;
    /// After a splat cloud of at least this many splats is added or updated, the next frame
    /// is preceded by one without splats showing "Drawing the first frame of N splats" in the
    /// panel, presented while that frame's geometry stage runs (seconds on a software
    /// device). 0: never.
    int64_t first_frame_notice_splats = 1000000;
};

struct RunOptions {
    /// Draw every loop iteration. Otherwise a frame is drawn only after input or a change
    /// (geometry, camera, settings, screenshot request, resize), and the loop sleeps on
    /// window events in between, so an idle viewer costs no CPU.
    bool continuous = false;
    /// Stop after this many drawn frames (0: until the window closes).
    int64_t max_frames = 0;
    /// Stop after this many seconds (0: no limit).
    double max_seconds = 0.0;
    /// Called before each frame is drawn (animation, scripted input; with continuous).
    std::function<void()> before_frame;
    /// Called on every loop iteration, drawn or idle (about ten times a second while idle):
    /// background work reports here (a finished load, progress in SetStatus).
    std::function<void()> poll;
    /// Return as soon as the visualizer is idle (IsIdle): everything asked for is drawn and
    /// a stream has settled. Scripts and tests wait for that event instead of a time
    /// (max_seconds then only bounds a hang). Ignored with `continuous`.
    bool until_idle = false;
};

/// A splat picked in the window (Visualizer::PickSplat).
struct SplatPick {
    std::string geometry;
    int64_t index = -1;  ///< in that geometry
    /// The world point on the pixel's ray at the view's expected depth there.
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    /// From the previous pick's point; -1 for the first pick.
    double distance_to_previous = -1.0;
    /// The splat's attributes as the renderer reads them: its centre, opacity after the
    /// sigmoid, scale (the axes' standard deviations), rotation (w, x, y, z) and degree-0
    /// colour 0.5 + C0 f_dc.
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    double opacity = 0.0;
    Eigen::Vector3d scale = Eigen::Vector3d::Zero();
    Eigen::Vector4d rotation = Eigen::Vector4d::Zero();
    Eigen::Vector3d color = Eigen::Vector3d::Zero();
};

class Visualizer : public WindowEventHandler {
public:
    /// Opens a window with its own Filament engine. Throws core::Open3DError when no X
    /// server or GL context is available (the message says to use xvfb-run) or a named
    /// backend cannot be made.
    explicit Visualizer(const VisualizerOptions& options = {});
    /// Opens a window drawn by an existing renderer (tests share one engine); `renderer`
    /// must outlive the visualizer.
    Visualizer(rendering::FilamentRenderer& renderer, const VisualizerOptions& options);
    ~Visualizer() override;
    Visualizer(const Visualizer&) = delete;
    Visualizer& operator=(const Visualizer&) = delete;

    // Geometry, by name (names are unique across clouds and meshes; errors throw
    // core::Open3DError and leave the scene unchanged).
    void AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud);
    void AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud,
                     const rendering::MaterialRecord& material);
    void AddGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh,
                     const rendering::MaterialRecord& material = {});
    void UpdateGeometry(const std::string& name, const t::geometry::PointCloud& cloud);
    void UpdateGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh);
    /// False when the name is unknown.
    bool RemoveGeometry(const std::string& name);
    void ShowGeometry(const std::string& name, bool show);
    bool HasGeometry(const std::string& name) const;
    bool IsGeometryVisible(const std::string& name) const;
    /// Streams a paged splat file (.gspages, written by gs-convert --pages) as the splat
    /// scene, in place of any earlier stream (docs/streaming.md "In the renderer and the
    /// viewer"): a coarse cut shows at once, finer pages arrive from a worker thread while
    /// the viewer stays interactive, and the panel shows the progress. Meshes stay; splat
    /// clouds cannot be added meanwhile. Throws core::Open3DError (nothing changes) while
    /// splat clouds are shown, for a refused file or options, or without the Vulkan backend.
    void StreamSplats(const std::string& path, const rendering::SplatStreamOptions& options = {});
    /// Ends the stream; false when there was none.
    bool StopStreaming();
    /// Hides or shows the stream (the panel's "stream" checkbox); throws when none runs.
    void ShowStream(bool show);
    bool IsStreamVisible() const;
    /// Where the stream stands (the panel's "Streaming" line); empty when not streaming.
    std::optional<rendering::SplatStreamProgress> GetStreamProgress() const;
    /// In the order they were added (the panel's order; keys 1-9 toggle the first nine).
    const std::vector<std::string>& GetGeometryNames() const { return names_; }

    // Camera. The orbit camera (GetViewControl) is the one truth; its image size is the
    // window's framebuffer size.
    /// Fits the visible geometry's bounds (a unit cube when nothing is visible) in view,
    /// from the home direction (ViewControl::FitBounds).
    void ResetCamera();
    void SetCamera(const camera::LookAtCamera& look_at);
    /// Takes the camera's pose and vertical field of view; the image size stays the
    /// window's, with square pixels and a centred principal point. The orbit centre is the
    /// point in front of the camera at the depth of the scene's centre.
    void SetCamera(const camera::PinholeCamera& camera);
    camera::PinholeCamera GetCamera() const { return view_control_.GetCamera(); }
    /// The orbit camera (asks for a redraw: the caller may move it).
    ViewControl& GetViewControl() {
        PostRedraw();
        return view_control_;
    }

    // Appearance.
    /// Linear RGBA where nothing is drawn.
    void SetBackground(const Eigen::Vector4f& rgba);
    const Eigen::Vector4f& GetBackground() const;
    /// Splat settings (SH degree cap, antialias, ...) used by every frame (asks for a
    /// redraw: the caller may change them).
    rendering::RenderConfig& GetSplatConfig() {
        PostRedraw();
        return scene_->GetSplatConfig();
    }
    /// The same settings, read only (no redraw: the panel reads them every frame, and an
    /// idle viewer must not draw).
    const rendering::RenderConfig& GetSplatConfig() const { return scene_->GetSplatConfig(); }
    /// A level-of-detail hierarchy of splat cloud `name`, built from it
    /// (t::geometry::BuildSplatHierarchy or a .lod file): while that cloud is the window's only
    /// one and shown, moving frames draw a cut that holds VisualizerOptions::lod_target_ms
    /// (docs/viewer.md "Level of detail"). nullptr drops it; so does UpdateGeometry. Throws
    /// when the cloud is unknown or the hierarchy was built from another.
    void SetSplatHierarchy(const std::string& name,
                           std::shared_ptr<const t::geometry::SplatHierarchy> hierarchy);
    void SetLodTargetMs(double ms);
    double GetLodTargetMs() const { return lod_target_ms_; }
    void SetSplatConfig(const rendering::RenderConfig& config) {
        PostRedraw();
        scene_->GetSplatConfig() = config;
    }
    void ShowSettings(bool show) {
        show_settings_ = show;
        PostRedraw();
    }
    bool IsSettingsShown() const { return show_settings_; }

    // The loop.
    /// Handles pending window events; false once the window was asked to close.
    bool PollEvents();
    /// Draws one frame to the window (panel included); false when nothing was drawn
    /// because the window is minimised (0 x 0 framebuffer).
    bool RenderFrame();
    /// Polls and draws until the window closes or a limit in `options` is reached.
    /// Minimised, it sleeps on events instead of drawing.
    void Run(const RunOptions& options = {});
    /// Makes Run draw the next frames even when no input arrives (after changing what
    /// the visualizer cannot see, e.g. a geometry edited through GetScene()).
    void PostRedraw() { redraw_frames_ = std::max(redraw_frames_, 2); }
    /// Asks the loop to end (Esc and Q do the same).
    void Close();
    /// True when Run would draw nothing more without new input: no frame is owed (input,
    /// a change, a reduced frame still to refine, a new stream progress line) and a stream,
    /// if any, has settled. Takes in what background work reported since the last call.
    bool IsIdle();

    // Images.
    /// Draws a frame and reads the window back: UInt8 [H, W, 3], top row first, exactly
    /// what the window shows (panel included). Throws while minimised.
    t::geometry::Image CaptureScreenImage();
    /// Writes the next drawn frame to screenshot_dir/screenshot_NNNN.png (P key, panel
    /// button) and returns that path; the file appears complete (written, then renamed).
    /// The frame waits until the panel has taken all earlier input (a click needs two) and
    /// shows new splats with their numbers in the panel; requests before it make one shot.
    std::string RequestScreenshot();
    /// Folder of later screenshots (made when missing).
    void SetScreenshotDir(const std::string& dir) { screenshot_dir_ = dir.empty() ? "." : dir; }
    /// Whether a requested screenshot waits for a frame (none drawn yet: minimised, loading,
    /// a cancelled frame).
    bool HasPendingScreenshot() const { return screenshot_pending_; }
    /// Path of the last screenshot written, empty before the first.
    const std::string& GetLastScreenshotPath() const { return last_screenshot_; }
    /// Why the last screenshot could not be written (shown in the panel; the viewer goes
    /// on), empty when it was.
    const std::string& GetLastScreenshotError() const { return screenshot_error_; }
    /// Offscreen render of the same scene and camera: UInt8 [H, W, 3] (or 4 with alpha).
    t::geometry::Image RenderToImage(bool with_alpha = false);
    /// Offscreen depth (Open3DScene::RenderToDepthImage: near / far default to the view's).
    t::geometry::Image RenderToDepthImage(
        rendering::DepthFormat format = rendering::DepthFormat::kViewZ,
        std::optional<float> near = std::nullopt, std::optional<float> far = std::nullopt);

    // Window.
    /// Requests a window size; the new size is used from the next frame on.
    void SetWindowSize(int width, int height);
    /// Framebuffer size in pixels (0 x 0 while minimised).
    int GetWidth() const { return fb_width_; }
    int GetHeight() const { return fb_height_; }
    void Minimize();
    void Maximize();
    void Restore();
    /// The X11 window id (for xdotool).
    uint64_t GetX11WindowId() const;

    // State for the panel, tests and logs.
    /// The last frame drawn to the window or offscreen (times, splat stats).
    const rendering::FrameResult& GetLastFrame() const { return last_frame_; }
    /// 1 when the last frame drawn to the window had the window's resolution, 2 or 4 when it
    /// was drawn at that fraction of each side (the camera was moving).
    int GetLastFrameDivisor() const { return last_divisor_; }
    /// A drag is orbiting or panning, or the camera moved by key or wheel (or
    /// NoteCameraMotion) in the last 0.25 s.
    bool IsCameraMoving() const;
    /// Counts as camera motion for 0.25 s: a scripted camera path (the example's --spin) gets
    /// the reduced frames of a moving camera on a slow device.
    void NoteCameraMotion();
    const FrameStatistics& GetFrameStatistics() const { return frame_stats_; }
    std::string GetBackendName() const;
    /// The scene behind the window (asks for a redraw).
    rendering::Open3DScene& GetScene() {
        PostRedraw();
        return *scene_;
    }
    /// Extra keys: called on every key press before the built-in shortcuts; return true
    /// to consume the key.
    void SetKeyCallback(std::function<bool(int key, int mods)> callback) {
        key_callback_ = std::move(callback);
    }
    /// Extra panel widgets, drawn at the end of the settings panel (ImGui calls).
    void SetPanelCallback(std::function<void()> callback) { panel_callback_ = std::move(callback); }
    /// Opening files: called with the paths dropped on the window or typed into the panel's
    /// "Open" field (shown only while a callback is set). The callback decides what to load
    /// (GaussianSplat replaces its scene); errors it throws are shown in the panel.
    void SetOpenCallback(std::function<void(const std::vector<std::string>& paths)> callback) {
        open_callback_ = std::move(callback);
        PostRedraw();
    }
    /// A line shown at the top of the panel (loading progress, errors); empty: none.
    /// `warning` draws it in the warning colour.
    void SetStatus(const std::string& text, bool warning = false) {
        status_ = text;
        status_warning_ = warning;
        PostRedraw();
    }
    const std::string& GetStatus() const { return status_; }

    // Editing splat clouds (docs/viewer.md "Editing"). Mouse and keys: Ctrl + click picks,
    // Ctrl + drag selects a rectangle, Ctrl + Alt + drag a lasso (with Shift either adds to
    // the selection), Delete removes the selected splats, Ctrl + I inverts the selection,
    // Ctrl + Z undoes a removal, K adds the camera as a keyframe of a camera path.
    /// The splat that contributes most to window pixel (x, y) (the composite's ID image of
    /// the current camera) and the point there; nullopt where no splat is. Kept in GetPicks.
    std::optional<SplatPick> PickSplat(int x, int y);
    /// Selects the splats of the visible clouds whose centre projects into the rectangle
    /// and that the view shows there (cpu::SelectSplatsInView, each cloud on its own);
    /// `add` keeps the earlier selection. Returns the number selected in all.
    int64_t SelectSplats(double x0, double y0, double x1, double y1, bool add = false);
    /// The same for a polygon of window pixels (a lasso; at least 3 vertices).
    int64_t SelectSplatsInPolygon(const std::vector<Eigen::Vector2d>& polygon, bool add = false);
    /// Every splat of the clouds that have a selection becomes selected but the selected
    /// ones. Returns the number selected in all.
    int64_t InvertSelection();
    void ClearSelection();
    /// Removes the selected splats from their clouds (UpdateGeometry; undoable). Returns
    /// the number removed.
    int64_t DeleteSelection();
    /// Keeps, of every visible splat cloud, the splats whose centre lies in `box` (with
    /// `invert`, outside it), undoable as one edit. Returns the number removed.
    int64_t CropSplats(const t::geometry::OrientedBoundingBox& box, bool invert = false);
    /// The axis-aligned box around the selected splats' centres, as an oriented box (the
    /// panel's "Crop to the selection's box"); throws when nothing is selected.
    t::geometry::OrientedBoundingBox GetSelectionBox() const;
    /// The crop box being edited, drawn in the window as its 12 edges (yellow points) and
    /// adjusted in the panel ("Crop box": its corners dragged with the mouse); nullopt ends it.
    void SetCropBox(const std::optional<t::geometry::AxisAlignedBoundingBox>& box);
    const std::optional<t::geometry::AxisAlignedBoundingBox>& GetCropBox() const {
        return crop_box_;
    }
    /// The box the panel's "Crop box" starts from: the selection's (GetSelectionBox), else the
    /// visible splat clouds' bounds; throws when no splat cloud is shown.
    t::geometry::AxisAlignedBoundingBox DefaultCropBox() const;
    /// CropSplats with the crop box (`invert`: removes what lies inside), then ends the box.
    /// Throws when there is none. Returns the number removed.
    int64_t ApplyCropBox(bool invert = false);
    /// Restores the clouds as they were before the last DeleteSelection or CropSplats;
    /// false when there is nothing to undo.
    bool UndoEdit();
    /// Selected splat indices per cloud (ascending).
    const std::map<std::string, std::vector<int64_t>>& GetSelection() const { return selection_; }
    const std::vector<SplatPick>& GetPicks() const { return picks_; }
    /// Writes splat cloud `name` as it stands (edits included) in any writable format
    /// (t::io::WritePointCloud; the extension decides). Throws naming the file.
    void SaveGeometry(const std::string& name, const std::string& path);
    /// Appends the current camera to the camera path being recorded, 2 s after the last
    /// keyframe (the first at 0 s); returns the number of keyframes.
    size_t AddKeyframe();
    /// The keyframes as cameras.json views with their times (gs-render --camera-path, Python
    /// CameraPath.from_cameras_json).
    const std::vector<camera::CameraView>& GetKeyframes() const { return keyframes_; }
    void ClearKeyframes() {
        keyframes_.clear();
        PostRedraw();
    }
    /// Writes the keyframes as cameras.json (camera::WriteCamerasJson); throws when there are
    /// none or the file cannot be written.
    void SaveKeyframes(const std::string& path) const;

    // WindowEventHandler: GLFW's callbacks arrive here; tests may inject events.
    void OnMouseButton(int button, bool pressed, int mods) override;
    void OnCursorPos(double x, double y) override;
    void OnScroll(double dx, double dy) override;
    void OnKey(int key, bool pressed, bool repeat, int mods) override;
    void OnChar(unsigned int codepoint) override;
    void OnFramebufferSize(int width, int height) override;
    void OnDrop(const std::vector<std::string>& paths) override;

private:
    enum class Drag { kNone, kRotate, kPan, kPanel, kSelect, kSelectAdd };

    void Init(const VisualizerOptions& options);
    void ToggleGeometry(size_t index);
    bool PanelContains(double x, double y) const;
    void BuildPanel();
    /// Runs the panel's ImGui frame (when shown); false while input is still pending.
    bool BuildOverlay();
    rendering::FrameResult DrawToWindow(bool read_screen, int divisor, bool skip_splats = false);
    /// Notes a splat cloud that was added or updated (the first-frame notice).
    void NoteNewSplats(const t::geometry::PointCloud& cloud);
    /// The resolution divisor of the next frame (VisualizerOptions::interactive_frame_ms).
    int InteractiveDivisor() const;
    /// While a frame is in flight its GPU waits poll window events (docs/viewer.md):
    /// handlers then keep the event for after the frame. True when `handler` was kept.
    bool DeferDuringFrame(std::function<void()> handler);
    void OpenFiles(const std::vector<std::string>& paths);
    void WriteScreenshot(const t::geometry::Image& rgb);
    /// screenshot_dir/screenshot_NNNN.png with the number the next written shot takes.
    std::string NextScreenshotPath() const;
    /// Owes frames for what changed without input: a reduced frame to refine, pages that
    /// arrived, a new stream progress line.
    void NoteBackgroundChanges();

    std::unique_ptr<rendering::FilamentEngine> owned_engine_;
    std::unique_ptr<rendering::FilamentRenderer> owned_renderer_;
    rendering::FilamentRenderer* renderer_ = nullptr;
    std::unique_ptr<VisualizerWindow> window_;
    std::unique_ptr<rendering::Open3DScene> scene_;
    std::string stream_line_;  // the streaming progress line of the last redraw it asked for
    std::unique_ptr<ImGuiOverlay> overlay_;
    ViewControl view_control_;
    std::vector<std::string> names_;

    int fb_width_ = 0, fb_height_ = 0;
    int overlay_width_ = 0, overlay_height_ = 0;
    double cursor_x_ = 0.0, cursor_y_ = 0.0;
    Drag drag_ = Drag::kNone;
    bool show_settings_ = true;
    int redraw_frames_ = 2;               // frames Run still draws without new input
    float panel_rect_[4] = {0, 0, 0, 0};  // x, y, w, h of the panel in the last frame
    double interactive_frame_ms_ = 100.0;
    double lod_target_ms_ = 0.0;
    int64_t first_frame_notice_splats_ = 1000000;
    int64_t new_splats_ = 0;       // splats added since the last frame drawn with splats
    double full_frame_ms_ = 0.0;   // time of the last full-resolution frame
    double last_motion_s_ = -1e9;  // steady clock seconds of the last key/wheel motion
    int last_divisor_ = 1;

    std::string screenshot_dir_;
    int screenshot_index_ = 0;
    // A screenshot is asked for: the next drawn frame is written, and only then does it take
    // its number (presses before that frame, during a load say, make one shot, not gaps).
    bool screenshot_pending_ = false;
    std::string last_screenshot_;
    std::string screenshot_error_;

    bool in_frame_ = false;                        // DrawToWindow is running
    std::vector<std::function<void()>> deferred_;  // events that arrived during it
    std::function<void(const std::vector<std::string>&)> open_callback_;
    char open_field_[1024] = {};  // the panel's "Open" text field
    std::string status_;
    bool status_warning_ = false;

    rendering::FrameResult last_frame_;
    FrameStatistics frame_stats_;
    double last_present_s_ = -1.0;  // steady clock seconds of the last presented frame
    std::function<bool(int, int)> key_callback_;
    std::function<void()> panel_callback_;

    // Editing (VisualizerEditing.cpp).
    /// A splat-editing shortcut (Delete, Ctrl + I, Ctrl + Z); true when consumed.
    bool OnEditKey(int key, int mods);
    /// The end of a Ctrl + drag: a pick where the mouse barely moved, else a selection.
    void EndSelectDrag(Drag drag);
    void DrawEditingPanel();
    /// Selected splats over all clouds.
    int64_t SelectedCount() const;
    /// After an edit replaced the clouds in `before` (as they were): one undo step; the
    /// selection and picks end (their indices named the old clouds).
    void CommitEdit(std::vector<std::pair<std::string, t::geometry::PointCloud>> before);
    /// After the clouds changed: their selection and picks named the splats before.
    void EndSelectionAndPicks();
    /// Draws the selection: red points at the selected centres, a scene geometry named
    /// kSelectionOverlay that is not one of the window's objects (none when nothing is
    /// selected).
    void UpdateSelectionOverlay();
    /// Adds unlit points of `color` to the scene as `name` (an overlay, not a window object);
    /// nothing for no points.
    void ShowOverlayPoints(const char* name, const std::vector<float>& points,
                           const Eigen::Vector4f& color, float point_size);
    /// Draws the crop box's edges as points (kCropBoxOverlay), or removes them without a box.
    void UpdateCropBoxOverlay();
    /// The panel's crop-box section: corners, the count inside, keep / remove / cancel.
    void DrawCropBoxPanel();
    /// Throws for the names the selection and crop-box overlays take.
    static void RequireObjectName(const std::string& name);
    static constexpr const char* kSelectionOverlay = "__selection__";
    static constexpr const char* kCropBoxOverlay = "__crop_box__";
    std::optional<t::geometry::AxisAlignedBoundingBox> crop_box_;
    int64_t crop_box_inside_ = 0;  // splats of the visible clouds inside, counted on each change
    std::map<std::string, std::vector<int64_t>> selection_;
    std::vector<SplatPick> picks_;
    // Per DeleteSelection, every cloud it changed as it was before.
    std::vector<std::vector<std::pair<std::string, t::geometry::PointCloud>>> undo_;
    double press_x_ = 0.0, press_y_ = 0.0;  // where a Ctrl + drag started
    bool lasso_ = false;                    // the Ctrl + drag is a lasso (Alt held)
    std::vector<Eigen::Vector2d> lasso_points_;
    std::vector<camera::CameraView> keyframes_;
    char edit_path_[1024] = {};  // the panel's file field for saving clouds and keyframes
    std::string edit_status_;    // the last edit error or save, shown in the panel
};

/// A geometry for Draw: a splat cloud or a mesh, by name.
/// A paged splat file (.gspages) for Draw to stream as the splat scene
/// (Visualizer::StreamSplats).
struct StreamedSplats {
    std::string path;
    rendering::SplatStreamOptions options;
};

struct DrawObject {
    std::string name;
    /// A stream is always shown (`visible` and `material` are for clouds and meshes).
    std::variant<t::geometry::PointCloud, t::geometry::TriangleMesh, StreamedSplats> geometry;
    /// How it is drawn (rendering::MaterialRecord); none: point clouds with the Gaussian
    /// attributes are splats, other point clouds points, meshes "defaultUnlit".
    std::optional<rendering::MaterialRecord> material;
    bool visible = true;
};

/// Open3D's draw(): opens a window with the objects, fits the camera, and runs until the
/// window closes (or `run` says otherwise).
void Draw(const std::vector<DrawObject>& objects, const VisualizerOptions& options = {},
          const RunOptions& run = {});

}  // namespace visualization
}  // namespace open3d
