// A visible GLFW window that Filament draws to (docs/viewer.md "Window"). The window has no
// client API (GLFW_NO_API) and 0 alpha bits (ENVIRONMENT.md: Filament's GLX surfaces need
// them); Filament makes its own GLX surface on the X11 window through
// Engine::createSwapChain(native window). GLFW's callbacks go to a WindowEventHandler.
// Needs a live FilamentEngine (it initialises GLFW); destroy the window first.
#pragma once

#include <cstdint>
#include <string>

#include "open3d/visualization/visualizer/WindowEventHandler.h"

struct GLFWwindow;
namespace filament {
class SwapChain;
}  // namespace filament

namespace open3d {
namespace visualization {

namespace rendering {
class FilamentEngine;
}  // namespace rendering

class VisualizerWindow {
public:
    /// Opens and shows the window. Throws core::Open3DError when GLFW or Filament cannot
    /// make it (the message says why).
    VisualizerWindow(rendering::FilamentEngine& engine, const std::string& title, int width,
                     int height, WindowEventHandler* handler);
    ~VisualizerWindow();
    VisualizerWindow(const VisualizerWindow&) = delete;
    VisualizerWindow& operator=(const VisualizerWindow&) = delete;

    /// Readable (CONFIG_READABLE), so screenshots can read it back.
    filament::SwapChain* GetSwapChain() const { return swap_chain_; }
    /// Drawable size in pixels; 0 x 0 while minimised.
    void GetFramebufferSize(int* width, int* height) const;
    /// The X11 window id (for xdotool and logs).
    uint64_t GetX11WindowId() const;

    bool ShouldClose() const;
    void SetShouldClose(bool close);
    void SetTitle(const std::string& title);
    /// Requests a new size; the window manager (if any) may adjust it, and the
    /// OnFramebufferSize callback reports what happened.
    void SetSize(int width, int height);
    void Iconify();
    void Restore();
    void Maximize();
    bool IsIconified() const;

    /// Handles pending events of all windows (callbacks run inside).
    static void PollEvents();
    /// Sleeps until an event arrives or `seconds` pass.
    static void WaitEvents(double seconds);

private:
    rendering::FilamentEngine& engine_;
    WindowEventHandler* handler_;
    GLFWwindow* window_ = nullptr;
    filament::SwapChain* swap_chain_ = nullptr;
};

}  // namespace visualization
}  // namespace open3d
