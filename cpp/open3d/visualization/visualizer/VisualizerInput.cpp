// The Visualizer's window input: mouse, scroll, keys, characters, resize and dropped files,
// from GLFW's callbacks (WindowEventHandler) or injected by tests. Events that arrive during a
// frame (its GPU waits poll events) are kept for after it (DeferDuringFrame).
#include <GLFW/glfw3.h>

#include <algorithm>
#include <exception>
#include <string>
#include <vector>

#include "open3d/core/Logging.h"
#include "open3d/visualization/visualizer/Visualizer.h"
#include "open3d/visualization/visualizer/filament/ImGuiOverlay.h"
#include "open3d/visualization/visualizer/filament/VisualizerWindow.h"

namespace open3d {
namespace visualization {

bool Visualizer::PanelContains(double x, double y) const {
    return show_settings_ && x >= panel_rect_[0] && y >= panel_rect_[1] &&
           x < panel_rect_[0] + panel_rect_[2] && y < panel_rect_[1] + panel_rect_[3];
}

void Visualizer::OnMouseButton(int button, bool pressed, int mods) {
    if (DeferDuringFrame([=, this] { OnMouseButton(button, pressed, mods); })) return;
    PostRedraw();
    if (!pressed) {
        overlay_->OnMouseButton(button, false);
        const Drag ended = drag_;
        drag_ = Drag::kNone;
        if (ended == Drag::kSelect || ended == Drag::kSelectAdd) EndSelectDrag(ended);
        return;
    }
    if (drag_ != Drag::kNone) return;  // one drag at a time
    if (PanelContains(cursor_x_, cursor_y_) || (show_settings_ && overlay_->HasPopup())) {
        drag_ = Drag::kPanel;
        overlay_->OnMouseButton(button, true);
    } else if (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_CONTROL)) {
        // Ctrl: a click picks, a drag selects (with shift: adds to the selection).
        drag_ = (mods & GLFW_MOD_SHIFT) ? Drag::kSelectAdd : Drag::kSelect;
        press_x_ = cursor_x_;
        press_y_ = cursor_y_;
        lasso_ = (mods & GLFW_MOD_ALT) != 0;
        lasso_points_.assign(1, Eigen::Vector2d(cursor_x_, cursor_y_));
    } else if (button == GLFW_MOUSE_BUTTON_LEFT && !(mods & GLFW_MOD_SHIFT)) {
        drag_ = Drag::kRotate;
    } else {
        drag_ = Drag::kPan;  // right, middle, or shift + left
    }
}

void Visualizer::OnCursorPos(double x, double y) {
    if (DeferDuringFrame([=, this] { OnCursorPos(x, y); })) return;
    const double dx = x - cursor_x_, dy = y - cursor_y_;
    cursor_x_ = x;
    cursor_y_ = y;
    overlay_->OnCursorPos(x, y);
    if (drag_ != Drag::kNone || show_settings_) PostRedraw();  // camera or panel hover
    if (drag_ == Drag::kRotate) view_control_.Rotate(dx, dy);
    if (drag_ == Drag::kPan) view_control_.Pan(dx, dy);
    if (drag_ == Drag::kRotate || drag_ == Drag::kPan) NoteCameraMotion();
    if (lasso_ && (drag_ == Drag::kSelect || drag_ == Drag::kSelectAdd)) {
        lasso_points_.emplace_back(x, y);
    }
}

void Visualizer::OnScroll(double dx, double dy) {
    if (DeferDuringFrame([=, this] { OnScroll(dx, dy); })) return;
    PostRedraw();
    if (PanelContains(cursor_x_, cursor_y_)) {
        overlay_->OnScroll(dx, dy);
    } else {
        view_control_.Zoom(dy);  // wheel up: closer
        NoteCameraMotion();
    }
}

void Visualizer::OnKey(int key, bool pressed, bool repeat, int mods) {
    if (in_frame_ && pressed && !repeat && (key == GLFW_KEY_ESCAPE || key == GLFW_KEY_Q) &&
        !overlay_->WantsTextInput()) {
        Close();  // now, so the frame in flight stops before its composite
    }
    if (DeferDuringFrame([=, this] { OnKey(key, pressed, repeat, mods); })) return;
    overlay_->OnKey(key, pressed, mods);
    PostRedraw();
    if (!pressed || overlay_->WantsTextInput()) return;
    if (!repeat && key_callback_ && key_callback_(key, mods)) return;
    if (!repeat && OnEditKey(key, mods)) return;
    const double step = view_control_.GetHeight() / 36.0;  // 5 degrees of orbit
    const bool shift = (mods & GLFW_MOD_SHIFT) != 0;
    switch (key) {  // the camera keys count as motion (reduced frames on slow devices)
        case GLFW_KEY_LEFT:
        case GLFW_KEY_RIGHT: {
            const double d = key == GLFW_KEY_LEFT ? -step : step;
            shift ? view_control_.Pan(d, 0.0) : view_control_.Rotate(d, 0.0);
            NoteCameraMotion();
            return;
        }
        case GLFW_KEY_UP:
        case GLFW_KEY_DOWN: {
            const double d = key == GLFW_KEY_UP ? -step : step;
            shift ? view_control_.Pan(0.0, d) : view_control_.Rotate(0.0, d);
            NoteCameraMotion();
            return;
        }
        case GLFW_KEY_EQUAL:
        case GLFW_KEY_KP_ADD:
            view_control_.Zoom(1.0);
            NoteCameraMotion();
            return;
        case GLFW_KEY_MINUS:
        case GLFW_KEY_KP_SUBTRACT:
            view_control_.Zoom(-1.0);
            NoteCameraMotion();
            return;
        default:
            break;
    }
    if (repeat) return;  // toggles fire once per press
    if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9) {
        ToggleGeometry(static_cast<size_t>(key - GLFW_KEY_1));
        return;
    }
    switch (key) {
        case GLFW_KEY_ESCAPE:
        case GLFW_KEY_Q:
            Close();
            break;
        case GLFW_KEY_R:
            ResetCamera();
            break;
        case GLFW_KEY_H:
            show_settings_ = !show_settings_;
            break;
        case GLFW_KEY_P:
            RequestScreenshot();
            break;
        default:
            break;
    }
}

void Visualizer::OnChar(unsigned int codepoint) {
    if (DeferDuringFrame([=, this] { OnChar(codepoint); })) return;
    overlay_->OnChar(codepoint);
    PostRedraw();
}

void Visualizer::OnFramebufferSize(int width, int height) {
    if (DeferDuringFrame([=, this] { OnFramebufferSize(width, height); })) return;
    if (width == fb_width_ && height == fb_height_) return;
    PostRedraw();
    fb_width_ = std::max(width, 0);
    fb_height_ = std::max(height, 0);
    // The targets of the old size go now, before anything of that size is drawn again;
    // while minimised (0 x 0) nothing is drawn and the camera keeps its last size.
    scene_->GetView().ReleaseTargets();
    if (fb_width_ > 0 && fb_height_ > 0) view_control_.SetViewSize(fb_width_, fb_height_);
}

void Visualizer::OnDrop(const std::vector<std::string>& paths) {
    if (DeferDuringFrame([=, this] { OnDrop(paths); })) return;
    OpenFiles(paths);
}

void Visualizer::OpenFiles(const std::vector<std::string>& paths) {
    if (paths.empty()) return;
    if (!open_callback_) {
        SetStatus("Opening files is not enabled in this viewer", true);
        return;
    }
    try {
        open_callback_(paths);
    } catch (const std::exception& e) {
        SetStatus(e.what(), true);
        core::LogWarning("{}", e.what());
    }
}

}  // namespace visualization
}  // namespace open3d
