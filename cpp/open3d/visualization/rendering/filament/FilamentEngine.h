// The Filament engine and the OpenGL context our own GL calls run in (docs/filament.md
// "Shared GL context"). A hidden GLFW window with an OpenGL 4.5 core context is created
// first, with 0 alpha bits (ENVIRONMENT.md: 8 alpha bits kill the first frame with an X
// BadMatch); Filament's OpenGL backend then creates its context sharing objects with it,
// so textures we make (imported Vulkan memory, host-copy textures) are Filament textures.
#pragma once

#include <memory>

#include "open3d/visualization/rendering/filament/GlFunctions.h"

struct GLFWwindow;
namespace filament {
class Engine;
}  // namespace filament

namespace open3d {
namespace visualization {
namespace rendering {

class FilamentEngine {
public:
    /// Throws core::Open3DError when no X server is reachable (Filament 1.9's OpenGL backend
    /// is GLX only and would exit the process: the message says to run under xvfb-run), when
    /// GLFW cannot make a 4.5 core context, or when Filament fails to start.
    FilamentEngine();
    ~FilamentEngine();
    FilamentEngine(const FilamentEngine&) = delete;
    FilamentEngine& operator=(const FilamentEngine&) = delete;

    filament::Engine& GetEngine() const { return *engine_; }
    /// Engine::flushAndWait, calling the thread's core::WaitCallback while Filament's
    /// thread works (the viewer's window stays responsive during long frames).
    void FlushAndWait() const;
    /// The hidden window whose context shares objects with Filament's.
    GLFWwindow* GetSharedContextWindow() const { return window_; }
    /// Makes the shared context current on this thread (the engine's thread).
    void MakeContextCurrent() const;
    /// Entry points of the shared context.
    const GlFunctions& GetGl() const { return gl_; }

private:
    GLFWwindow* window_ = nullptr;
    filament::Engine* engine_ = nullptr;
    GlFunctions gl_;
};

/// Why no Filament engine can start here (no DISPLAY, no X server reachable, no GLFW), or
/// an empty string when one can. Cheap; tests use it to skip with the reason.
std::string FilamentUnavailableReason();

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
