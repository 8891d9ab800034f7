#include "open3d/visualization/visualizer/filament/VisualizerWindow.h"

#include <GLFW/glfw3.h>
#define GLFW_EXPOSE_NATIVE_X11
#include <GLFW/glfw3native.h>
#include <filament/Engine.h>
#include <filament/SwapChain.h>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"

namespace open3d {
namespace visualization {

namespace {

WindowEventHandler* HandlerOf(GLFWwindow* window) {
    return static_cast<WindowEventHandler*>(glfwGetWindowUserPointer(window));
}

void InstallCallbacks(GLFWwindow* window) {
    glfwSetMouseButtonCallback(window, [](GLFWwindow* w, int button, int action, int mods) {
        HandlerOf(w)->OnMouseButton(button, action == GLFW_PRESS, mods);
    });
    glfwSetCursorPosCallback(
        window, [](GLFWwindow* w, double x, double y) { HandlerOf(w)->OnCursorPos(x, y); });
    glfwSetScrollCallback(
        window, [](GLFWwindow* w, double dx, double dy) { HandlerOf(w)->OnScroll(dx, dy); });
    glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int, int action, int mods) {
        HandlerOf(w)->OnKey(key, action != GLFW_RELEASE, action == GLFW_REPEAT, mods);
    });
    glfwSetCharCallback(
        window, [](GLFWwindow* w, unsigned int codepoint) { HandlerOf(w)->OnChar(codepoint); });
    glfwSetFramebufferSizeCallback(window, [](GLFWwindow* w, int width, int height) {
        HandlerOf(w)->OnFramebufferSize(width, height);
    });
    glfwSetDropCallback(window, [](GLFWwindow* w, int count, const char** paths) {
        HandlerOf(w)->OnDrop(std::vector<std::string>(paths, paths + count));
    });
}

}  // namespace

VisualizerWindow::VisualizerWindow(rendering::FilamentEngine& engine, const std::string& title,
                                   int width, int height, WindowEventHandler* handler)
    : engine_(engine), handler_(handler) {
    if (width <= 0 || height <= 0) {
        core::ThrowError("VisualizerWindow: size must be positive, got {}x{}", width, height);
    }
    // GLFW is initialised by the engine (FilamentEngine), which outlives this window.
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);  // Filament makes the GLX surface
    glfwWindowHint(GLFW_ALPHA_BITS, 0);            // 8 alpha bits: X BadMatch on the first frame
    glfwWindowHint(GLFW_VISIBLE, GLFW_TRUE);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
    window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (window_ == nullptr) {
        const char* description = nullptr;
        glfwGetError(&description);
        core::ThrowError("VisualizerWindow: GLFW could not open a {}x{} window ({})", width, height,
                         description ? description : "no reason given");
    }
    glfwSetWindowUserPointer(window_, handler_);
    InstallCallbacks(window_);
    const Window x11_window = glfwGetX11Window(window_);
    swap_chain_ = engine_.GetEngine().createSwapChain(reinterpret_cast<void*>(x11_window),
                                                      filament::SwapChain::CONFIG_READABLE);
    if (swap_chain_ == nullptr) {
        glfwDestroyWindow(window_);
        core::ThrowError("VisualizerWindow: Filament could not make a swap chain for the window");
    }
    // Filament may have made its context current on this thread; our GL calls need ours.
    engine_.MakeContextCurrent();
}

VisualizerWindow::~VisualizerWindow() {
    filament::Engine& engine = engine_.GetEngine();
    engine.destroy(swap_chain_);
    // The GLX surface must be gone before the X window it lives on.
    engine.flushAndWait();
    glfwDestroyWindow(window_);
    engine_.MakeContextCurrent();
}

void VisualizerWindow::GetFramebufferSize(int* width, int* height) const {
    glfwGetFramebufferSize(window_, width, height);
}

uint64_t VisualizerWindow::GetX11WindowId() const { return glfwGetX11Window(window_); }

bool VisualizerWindow::ShouldClose() const { return glfwWindowShouldClose(window_) != 0; }
void VisualizerWindow::SetShouldClose(bool close) {
    glfwSetWindowShouldClose(window_, close ? GLFW_TRUE : GLFW_FALSE);
}
void VisualizerWindow::SetTitle(const std::string& title) {
    glfwSetWindowTitle(window_, title.c_str());
}
void VisualizerWindow::SetSize(int width, int height) { glfwSetWindowSize(window_, width, height); }
void VisualizerWindow::Iconify() { glfwIconifyWindow(window_); }
void VisualizerWindow::Restore() { glfwRestoreWindow(window_); }
void VisualizerWindow::Maximize() { glfwMaximizeWindow(window_); }
bool VisualizerWindow::IsIconified() const {
    return glfwGetWindowAttrib(window_, GLFW_ICONIFIED) != 0;
}

void VisualizerWindow::PollEvents() { glfwPollEvents(); }
void VisualizerWindow::WaitEvents(double seconds) { glfwWaitEventsTimeout(seconds); }

}  // namespace visualization
}  // namespace open3d
