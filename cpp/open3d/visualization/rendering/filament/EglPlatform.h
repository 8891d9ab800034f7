// Headless OpenGL through EGL (docs/filament.md "Headless: the EGL platform"): our own
// context and the Filament platform whose context shares objects with it, with no X server.
// Only offscreen rendering: a window's swap chain needs the GLX platform (GLFW).
#pragma once

#include <memory>
#include <string>

namespace filament {
namespace backend {
class Platform;
}  // namespace backend
}  // namespace filament

namespace open3d {
namespace visualization {
namespace rendering {

/// An EGL display with an OpenGL 4.5 core context and a small pbuffer for our own GL calls.
class EglContext {
public:
    /// Opens the first display that initializes: a hardware EGL device (EGL_EXT_platform_device),
    /// else Mesa's surfaceless platform, else a software device, else the default display.
    /// Throws core::Open3DError naming what failed.
    EglContext();
    ~EglContext();
    EglContext(const EglContext&) = delete;
    EglContext& operator=(const EglContext&) = delete;

    /// Makes the context current on the calling thread (binds the OpenGL API first).
    void MakeCurrent() const;
    void ReleaseCurrent() const;
    /// The EGLContext, given to Filament as its shared context.
    void* NativeContext() const { return context_; }
    void* NativeDisplay() const { return display_; }
    /// The EGLConfig of the context and its pbuffer (RGB8, pbuffers, OpenGL).
    void* NativeConfig() const { return config_; }
    /// Which display was opened, e.g. "EGL device 0 (EGL_NV_device_cuda), NVIDIA".
    const std::string& Description() const { return description_; }

    /// eglGetProcAddress, the loader of GlFunctions.
    static void* GetProcAddress(const char* name);

private:
    // Destroys the pbuffer and the context (the constructor's failure path and the destructor).
    void Release();

    void* display_ = nullptr;
    void* config_ = nullptr;
    void* context_ = nullptr;
    void* surface_ = nullptr;
    std::string description_;
};

/// Filament's OpenGL platform on `context`'s display: its driver thread gets a context that
/// shares objects with `context` and a 1x1 pbuffer; headless swap chains are pbuffers; a
/// window's swap chain is refused (an error in the log and no swap chain).
std::unique_ptr<filament::backend::Platform> CreateEglFilamentPlatform(const EglContext& context);

/// Why no EGL display with an OpenGL 4.5 core context can be opened here, or "".
std::string EglUnavailableReason();

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
