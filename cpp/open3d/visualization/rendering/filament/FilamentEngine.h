// The Filament engine and the OpenGL context our own GL calls run in (docs/filament.md
// "Shared GL context"). Our OpenGL 4.5 core context is created first: on GLX a hidden GLFW
// window with 0 alpha bits (ENVIRONMENT.md: 8 alpha bits kill the first frame with an X
// BadMatch), on EGL a pbuffer with no X server (EglPlatform.h). Filament's OpenGL backend
// then creates its context sharing objects with it, so textures we make (imported Vulkan
// memory, host-copy textures) are Filament textures.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "open3d/visualization/rendering/filament/GlFunctions.h"

struct GLFWwindow;
namespace filament {
class Engine;
class SwapChain;
namespace backend {
class Platform;
}  // namespace backend
}  // namespace filament

namespace open3d {
namespace visualization {
namespace rendering {

class EglContext;
class DriverThreadHook;

/// How the OpenGL contexts are made. kGlx: an X server (GLFW windows, the viewer); kEgl:
/// headless, offscreen only; kAuto: kGlx where DISPLAY is set, else kEgl. The environment
/// variable OPEN3D_FILAMENT_PLATFORM (auto, glx, egl) overrides kAuto.
enum class GlPlatform { kAuto, kGlx, kEgl };

/// kAuto resolved: OPEN3D_FILAMENT_PLATFORM, else DISPLAY. Throws core::Open3DError naming
/// the variable when it holds something else than auto, glx or egl.
GlPlatform ResolveGlPlatform(GlPlatform platform);

class FilamentEngine {
public:
    /// Throws core::Open3DError when the platform cannot start: on GLX no X server reachable
    /// (Filament 1.9's GLX backend would exit the process: the message says to run under
    /// xvfb-run) or no 4.5 core context from GLFW; on EGL no display or context; or when
    /// Filament fails to start.
    explicit FilamentEngine(GlPlatform platform = GlPlatform::kAuto);
    ~FilamentEngine();
    FilamentEngine(const FilamentEngine&) = delete;
    FilamentEngine& operator=(const FilamentEngine&) = delete;

    filament::Engine& GetEngine() const { return *engine_; }
    /// Engine::flushAndWait, calling the thread's core::WaitCallback while Filament's
    /// thread works (the viewer's window stays responsive during long frames).
    void FlushAndWait() const;
    /// Hands the commands issued so far to Filament's thread without waiting for them.
    void Flush() const;
    /// Runs `action` on Filament's driver thread, its GL context current, after the commands
    /// issued so far and before later ones (FilamentDriverThread.h), once flushed. False, and
    /// nothing runs, where Filament's command stream could not be located.
    bool RunOnDriverThread(std::function<void()> action) const;
    /// Whether RunOnDriverThread runs actions.
    bool CanRunOnDriverThread() const;
    /// Why RunOnDriverThread cannot run actions ("" when it can).
    std::string DriverThreadUnavailableReason() const;
    /// The hidden window whose context shares objects with Filament's (null on EGL).
    GLFWwindow* GetSharedContextWindow() const { return window_; }
    /// kGlx or kEgl.
    GlPlatform GetPlatform() const { return platform_; }
    /// "GLX" or the EGL display opened, for messages and logs.
    std::string DescribePlatform() const;
    /// Makes the shared context current on this thread (the engine's thread).
    void MakeContextCurrent() const;
    /// Entry points of the shared context.
    const GlFunctions& GetGl() const { return gl_; }

private:
    void StartGlx();
    void StartEgl();

    GlPlatform platform_;
    GLFWwindow* window_ = nullptr;
    // EGL: Vulkan drivers kept loaded while the EGL display lives (NVIDIA's ends it when
    // unloaded); declared first, so it goes last.
    std::shared_ptr<void> vulkan_drivers_;
    std::unique_ptr<EglContext> egl_;
    std::unique_ptr<filament::backend::Platform> filament_platform_;  // EGL: outlives engine_
    filament::Engine* engine_ = nullptr;
    std::unique_ptr<DriverThreadHook> driver_hook_;
    GlFunctions gl_;
};

/// A swap chain with no window (a pbuffer surface of width x height): frames presented
/// offscreen, as the viewer presents them to its window, e.g. to time them.
class HeadlessSwapChain {
public:
    HeadlessSwapChain(const FilamentEngine& engine, int width, int height);
    ~HeadlessSwapChain();
    HeadlessSwapChain(const HeadlessSwapChain&) = delete;
    HeadlessSwapChain& operator=(const HeadlessSwapChain&) = delete;
    filament::SwapChain* Get() const { return swap_chain_; }

private:
    const FilamentEngine& engine_;
    filament::SwapChain* swap_chain_ = nullptr;
};

/// Why no Filament engine of `platform` can start here (GLX: no DISPLAY, no X server
/// reachable, no GLFW; EGL: no display or context), or an empty string when one can. Cheap;
/// tests use it to skip with the reason.
std::string FilamentUnavailableReason(GlPlatform platform = GlPlatform::kAuto);

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
