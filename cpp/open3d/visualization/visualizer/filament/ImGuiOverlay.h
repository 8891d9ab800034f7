// Dear ImGui drawn by Filament (docs/viewer.md "Panel"): filagui::ImGuiHelper turns ImGui's
// draw lists into renderables of its own scene, shown by a translucent Filament view that
// the renderer draws after the compose view (FrameRequest::overlay_views), so the panel
// lies over meshes and splats alike and is part of screenshots. Input arrives in GLFW's
// terms and is written into this overlay's ImGui context (no imgui_impl_glfw: the window's
// callbacks belong to the visualizer).
#pragma once

#include <functional>
#include <memory>

struct ImGuiContext;
namespace filament {
class View;
}  // namespace filament
namespace filagui {
class ImGuiHelper;
}  // namespace filagui

namespace open3d {
namespace visualization {

namespace rendering {
class FilamentEngine;
}  // namespace rendering

class ImGuiOverlay {
public:
    /// Own ImGui context (no imgui.ini is written), the built-in font, the dark style.
    explicit ImGuiOverlay(rendering::FilamentEngine& engine);
    ~ImGuiOverlay();
    ImGuiOverlay(const ImGuiOverlay&) = delete;
    ImGuiOverlay& operator=(const ImGuiOverlay&) = delete;

    /// The view to draw after the scene (its viewport follows SetSize).
    filament::View* GetView() const { return view_; }
    /// Display size in pixels (the framebuffer size).
    void SetSize(int width, int height);
    /// Runs one ImGui frame: `build` makes the widgets (ImGui calls), then the draw lists
    /// become Filament renderables. Call every drawn frame, before the renderer draws.
    void Build(double seconds_since_last, const std::function<void()>& build);

    // Input, in GLFW codes. Positions in pixels from the top left.
    void OnCursorPos(double x, double y);
    void OnMouseButton(int button, bool pressed);
    void OnScroll(double dx, double dy);
    void OnKey(int key, bool pressed, int mods);
    void OnChar(unsigned int codepoint);
    /// An ImGui text field has the keyboard: shortcuts must not fire.
    bool WantsTextInput() const;
    /// A popup (a colour picker, say) is open: clicks anywhere belong to ImGui.
    bool HasPopup() const;
    /// Input arrived that the last Build did not show ImGui yet (a click whose press and
    /// release came between two frames is shown as pressed in one frame, released in the
    /// next): draw another frame.
    bool HasPendingInput() const;

private:
    void MakeCurrent() const;

    rendering::FilamentEngine& engine_;
    filament::View* view_ = nullptr;
    ImGuiContext* context_ = nullptr;  // owned by helper_ (destroyed with it)
    std::unique_ptr<filagui::ImGuiHelper> helper_;
    static constexpr int kButtons = 5;
    bool button_down_[kButtons] = {};     // GLFW's state
    bool button_pressed_[kButtons] = {};  // pressed since the last Build
};

}  // namespace visualization
}  // namespace open3d
