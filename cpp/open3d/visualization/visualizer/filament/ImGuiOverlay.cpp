#include "open3d/visualization/visualizer/filament/ImGuiOverlay.h"

#include <GLFW/glfw3.h>
#include <filagui/ImGuiHelper.h>
#include <filament/Engine.h>
#include <filament/View.h>
#include <filament/Viewport.h>
#include <imgui.h>

#include <algorithm>

#include "open3d/visualization/rendering/filament/FilamentEngine.h"

namespace open3d {
namespace visualization {

namespace {

// ImGui 1.86 reads keys through KeyMap (ImGuiKey -> our key code) and KeysDown[code].
void MapKeys(ImGuiIO& io) {
    io.KeyMap[ImGuiKey_Tab] = GLFW_KEY_TAB;
    io.KeyMap[ImGuiKey_LeftArrow] = GLFW_KEY_LEFT;
    io.KeyMap[ImGuiKey_RightArrow] = GLFW_KEY_RIGHT;
    io.KeyMap[ImGuiKey_UpArrow] = GLFW_KEY_UP;
    io.KeyMap[ImGuiKey_DownArrow] = GLFW_KEY_DOWN;
    io.KeyMap[ImGuiKey_PageUp] = GLFW_KEY_PAGE_UP;
    io.KeyMap[ImGuiKey_PageDown] = GLFW_KEY_PAGE_DOWN;
    io.KeyMap[ImGuiKey_Home] = GLFW_KEY_HOME;
    io.KeyMap[ImGuiKey_End] = GLFW_KEY_END;
    io.KeyMap[ImGuiKey_Insert] = GLFW_KEY_INSERT;
    io.KeyMap[ImGuiKey_Delete] = GLFW_KEY_DELETE;
    io.KeyMap[ImGuiKey_Backspace] = GLFW_KEY_BACKSPACE;
    io.KeyMap[ImGuiKey_Space] = GLFW_KEY_SPACE;
    io.KeyMap[ImGuiKey_Enter] = GLFW_KEY_ENTER;
    io.KeyMap[ImGuiKey_Escape] = GLFW_KEY_ESCAPE;
    io.KeyMap[ImGuiKey_KeyPadEnter] = GLFW_KEY_KP_ENTER;
    io.KeyMap[ImGuiKey_A] = GLFW_KEY_A;
    io.KeyMap[ImGuiKey_C] = GLFW_KEY_C;
    io.KeyMap[ImGuiKey_V] = GLFW_KEY_V;
    io.KeyMap[ImGuiKey_X] = GLFW_KEY_X;
    io.KeyMap[ImGuiKey_Y] = GLFW_KEY_Y;
    io.KeyMap[ImGuiKey_Z] = GLFW_KEY_Z;
}

}  // namespace

ImGuiOverlay::ImGuiOverlay(rendering::FilamentEngine& engine) : engine_(engine) {
    IMGUI_CHECKVERSION();  // our imgui.h against the ImGui inside libfilament_filagui
    filament::Engine& e = engine_.GetEngine();
    view_ = e.createView();
    context_ = ImGui::CreateContext();
    ImGui::SetCurrentContext(context_);
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;  // no imgui.ini in the working directory
    io.LogFilename = nullptr;
    MapKeys(io);
    // An empty font path keeps ImGui's built-in font. The helper sets the view's scene,
    // camera and translucent blending.
    helper_ = std::make_unique<filagui::ImGuiHelper>(&e, view_, utils::Path(), context_);
}

ImGuiOverlay::~ImGuiOverlay() {
    helper_.reset();  // destroys its scene, renderables and the ImGui context
    engine_.GetEngine().destroy(view_);
}

void ImGuiOverlay::MakeCurrent() const { ImGui::SetCurrentContext(context_); }

void ImGuiOverlay::SetSize(int width, int height) {
    MakeCurrent();
    helper_->setDisplaySize(width, height);
    view_->setViewport({0, 0, uint32_t(width), uint32_t(height)});
}

void ImGuiOverlay::Build(double seconds_since_last, const std::function<void()>& build) {
    MakeCurrent();
    // ImGui asserts on a zero time step.
    const float dt = static_cast<float>(std::max(seconds_since_last, 1e-4));
    // ImGui 1.86 samples the buttons once per frame: a press is shown for a frame even when
    // its release came before the frame (slow frames on a software GPU).
    ImGuiIO& io = ImGui::GetIO();
    for (int b = 0; b < kButtons; ++b) {
        io.MouseDown[b] = button_down_[b] || button_pressed_[b];
        button_pressed_[b] = false;
    }
    helper_->render(dt, [&build](filament::Engine*, filament::View*) { build(); });
    // Wheel steps are consumed by the frame that saw them.
    io.MouseWheel = 0.0f;
    io.MouseWheelH = 0.0f;
}

void ImGuiOverlay::OnCursorPos(double x, double y) {
    MakeCurrent();
    ImGui::GetIO().MousePos = ImVec2(float(x), float(y));
}

void ImGuiOverlay::OnMouseButton(int button, bool pressed) {
    if (button < 0 || button >= kButtons) return;
    button_down_[button] = pressed;
    if (pressed) button_pressed_[button] = true;
}

bool ImGuiOverlay::HasPendingInput() const {
    MakeCurrent();
    const ImGuiIO& io = ImGui::GetIO();
    for (int b = 0; b < kButtons; ++b) {
        if (button_pressed_[b] || io.MouseDown[b] != button_down_[b]) return true;
    }
    return false;
}

void ImGuiOverlay::OnScroll(double dx, double dy) {
    MakeCurrent();
    ImGuiIO& io = ImGui::GetIO();
    io.MouseWheelH += float(dx);
    io.MouseWheel += float(dy);
}

void ImGuiOverlay::OnKey(int key, bool pressed, int mods) {
    MakeCurrent();
    ImGuiIO& io = ImGui::GetIO();
    if (key >= 0 && key < IM_ARRAYSIZE(io.KeysDown)) io.KeysDown[key] = pressed;
    io.KeyCtrl = (mods & GLFW_MOD_CONTROL) != 0;
    io.KeyShift = (mods & GLFW_MOD_SHIFT) != 0;
    io.KeyAlt = (mods & GLFW_MOD_ALT) != 0;
    io.KeySuper = (mods & GLFW_MOD_SUPER) != 0;
}

void ImGuiOverlay::OnChar(unsigned int codepoint) {
    MakeCurrent();
    ImGui::GetIO().AddInputCharacter(codepoint);
}

bool ImGuiOverlay::WantsTextInput() const {
    MakeCurrent();
    return ImGui::GetIO().WantTextInput;
}

bool ImGuiOverlay::HasPopup() const {
    MakeCurrent();
    return ImGui::IsPopupOpen("", ImGuiPopupFlags_AnyPopupId | ImGuiPopupFlags_AnyPopupLevel);
}

}  // namespace visualization
}  // namespace open3d
