#include "open3d/visualization/rendering/filament/EglPlatform.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/visualization/rendering/filament/FilamentOpenGLPlatform.h"

namespace open3d {
namespace visualization {
namespace rendering {

namespace {

bool HasToken(const char* list, const char* token) {
    if (list == nullptr) return false;
    const size_t n = std::strlen(token);
    for (const char* p = list; (p = std::strstr(p, token)) != nullptr; p += n) {
        const bool starts = p == list || p[-1] == ' ';
        const bool ends = p[n] == '\0' || p[n] == ' ';
        if (starts && ends) return true;
    }
    return false;
}

template <typename T>
T Proc(const char* name) {
    return reinterpret_cast<T>(eglGetProcAddress(name));
}

struct Candidate {
    EGLenum platform;
    void* native;
    std::string description;
};

// Set while displays are tried one after another: their failures are expected, and the
// one that matters is reported by the caller.
thread_local bool trying_displays = false;

// EGL_KHR_debug: the driver's own words for an EGL error (which call, why), logged with the
// calling thread, since a failed eglMakeCurrent on Filament's thread surfaces only later as
// libepoxy's "Couldn't find current GLX or EGL context". Installed once per process.
void EGLAPIENTRY OnEglDebugMessage(EGLenum error, const char* command, EGLint type, EGLLabelKHR,
                                   EGLLabelKHR, const char* message) {
    if (trying_displays) return;
    if (type != EGL_DEBUG_MSG_CRITICAL_KHR && type != EGL_DEBUG_MSG_ERROR_KHR) return;
    core::LogWarning("EGL error 0x{:x} in {} (thread {}): {}", error, command ? command : "?",
                     std::hash<std::thread::id>{}(std::this_thread::get_id()) % 100000,
                     message ? message : "");
}

void InstallEglDebugCallback(const char* client_extensions) {
    static std::once_flag once;
    std::call_once(once, [client_extensions] {
        if (!HasToken(client_extensions, "EGL_KHR_debug")) return;
        auto control = Proc<PFNEGLDEBUGMESSAGECONTROLKHRPROC>("eglDebugMessageControlKHR");
        const EGLAttrib attributes[] = {EGL_DEBUG_MSG_CRITICAL_KHR, EGL_TRUE,
                                        EGL_DEBUG_MSG_ERROR_KHR, EGL_TRUE, EGL_NONE};
        if (control) control(OnEglDebugMessage, attributes);
    });
}

// Hardware devices first (their GL can share memory with the Vulkan device), then Mesa's
// surfaceless platform, software devices, and the default display.
std::vector<Candidate> Candidates() {
    std::vector<Candidate> hardware, software;
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    InstallEglDebugCallback(client);
    if (HasToken(client, "EGL_EXT_platform_device")) {
        auto query_devices = Proc<PFNEGLQUERYDEVICESEXTPROC>("eglQueryDevicesEXT");
        auto query_string = Proc<PFNEGLQUERYDEVICESTRINGEXTPROC>("eglQueryDeviceStringEXT");
        EGLint count = 0;
        if (query_devices && query_string && query_devices(0, nullptr, &count) && count > 0) {
            std::vector<EGLDeviceEXT> devices(count);
            query_devices(count, devices.data(), &count);
            for (EGLint i = 0; i < count; ++i) {
                const char* ext = query_string(devices[i], EGL_EXTENSIONS);
                const bool soft = HasToken(ext, "EGL_MESA_device_software");
                Candidate c{EGL_PLATFORM_DEVICE_EXT, devices[i],
                            fmt::format("EGL device {}{}", i, soft ? " (software)" : "")};
                (soft ? software : hardware).push_back(c);
            }
        }
    }
    std::vector<Candidate> all = hardware;
    if (HasToken(client, "EGL_MESA_platform_surfaceless")) {
        all.push_back({EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY,
                       "Mesa's surfaceless EGL platform"});
    }
    all.insert(all.end(), software.begin(), software.end());
    all.push_back({EGL_NONE, EGL_DEFAULT_DISPLAY, "the default EGL display"});
    return all;
}

// The display of a device is one per process: whoever calls eglTerminate ends it for every
// user. NVIDIA's Vulkan driver does when the loader unloads it; FilamentEngine keeps the
// Vulkan drivers loaded while it uses EGL (docs/environment-notes.md "NVIDIA GPUs").
EGLDisplay OpenDisplay(std::string* description, std::string* tried) {
    auto get_platform_display = Proc<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
    const std::vector<Candidate> candidates = Candidates();
    trying_displays = true;
    struct Done {
        ~Done() { trying_displays = false; }
    } done;
    for (const Candidate& c : candidates) {
        EGLDisplay display = EGL_NO_DISPLAY;
        if (c.platform == EGL_NONE) {
            display = eglGetDisplay(EGL_DEFAULT_DISPLAY);
        } else if (get_platform_display) {
            display = get_platform_display(c.platform, c.native, nullptr);
        }
        EGLint major = 0, minor = 0;
        if (display != EGL_NO_DISPLAY && eglInitialize(display, &major, &minor)) {
            const char* vendor = eglQueryString(display, EGL_VENDOR);
            *description = fmt::format("{}, EGL {}.{} of {}", c.description, major, minor,
                                       vendor ? vendor : "?");
            return display;
        }
        *tried += fmt::format("{}{} (EGL error 0x{:x})", tried->empty() ? "" : ", ", c.description,
                              eglGetError());
    }
    return EGL_NO_DISPLAY;
}

EGLConfig ChooseConfig(EGLDisplay display) {
    const EGLint attributes[] = {EGL_SURFACE_TYPE,
                                 EGL_PBUFFER_BIT,
                                 EGL_RENDERABLE_TYPE,
                                 EGL_OPENGL_BIT,
                                 EGL_RED_SIZE,
                                 8,
                                 EGL_GREEN_SIZE,
                                 8,
                                 EGL_BLUE_SIZE,
                                 8,
                                 EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (!eglChooseConfig(display, attributes, &config, 1, &count) || count == 0) return nullptr;
    return config;
}

// An OpenGL 4.5 core context (llvmpipe has no 4.6, ENVIRONMENT.md), sharing with `share`.
EGLContext CreateContext(EGLDisplay display, EGLConfig config, EGLContext share) {
    eglBindAPI(EGL_OPENGL_API);
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                 4,
                                 EGL_CONTEXT_MINOR_VERSION,
                                 5,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                 EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                 EGL_NONE};
    return eglCreateContext(display, config, share, attributes);
}

EGLSurface CreatePbuffer(EGLDisplay display, EGLConfig config, uint32_t width, uint32_t height) {
    const EGLint attributes[] = {EGL_WIDTH, EGLint(width), EGL_HEIGHT, EGLint(height), EGL_NONE};
    return eglCreatePbufferSurface(display, config, attributes);
}

// Filament 1.9.25's OpenGL platform on EGL; Filament calls it from its driver thread, whose
// context createDriver makes.
class EglFilamentPlatform final : public filament::backend::OpenGLPlatform {
public:
    explicit EglFilamentPlatform(const EglContext& shared)
        : display_(shared.NativeDisplay()),
          config_(shared.NativeConfig()),
          shared_(shared.NativeContext()) {}

    int getOSVersion() const noexcept override { return 0; }

    filament::backend::Driver* createDriver(void* shared_context) noexcept override {
        context_ = CreateContext(display_, config_, shared_);
        if (context_ == EGL_NO_CONTEXT) {
            core::LogError("Filament on EGL: eglCreateContext failed (EGL error 0x{:x})",
                           eglGetError());
            return nullptr;
        }
        pbuffer_ = CreatePbuffer(display_, config_, 1, 1);
        if (!eglMakeCurrent(display_, pbuffer_, pbuffer_, context_)) {
            core::LogError("Filament on EGL: eglMakeCurrent failed (EGL error 0x{:x})",
                           eglGetError());
            return nullptr;
        }
        return createDefaultDriver(this, shared_context);
    }

    void terminate() noexcept override {
        eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (pbuffer_ != EGL_NO_SURFACE) eglDestroySurface(display_, pbuffer_);
        if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
        pbuffer_ = EGL_NO_SURFACE;
        context_ = EGL_NO_CONTEXT;
    }

    SwapChain* createSwapChain(void*, uint64_t&) noexcept override {
        core::LogError(
            "Filament on EGL draws offscreen only: a window's swap chain needs the GLX "
            "platform (OPEN3D_FILAMENT_PLATFORM=glx and an X server)");
        return nullptr;
    }
    SwapChain* createSwapChain(uint32_t width, uint32_t height, uint64_t&) noexcept override {
        return new Surface{CreatePbuffer(display_, config_, width, height)};
    }
    void destroySwapChain(SwapChain* swap_chain) noexcept override {
        auto* surface = static_cast<Surface*>(swap_chain);
        if (surface == nullptr) return;
        if (surface->surface != EGL_NO_SURFACE) {
            // A surface current on this thread is released with the default one current.
            eglMakeCurrent(display_, pbuffer_, pbuffer_, context_);
            eglDestroySurface(display_, surface->surface);
        }
        delete surface;
    }
    void makeCurrent(SwapChain* draw, SwapChain* read) noexcept override {
        if (!eglMakeCurrent(display_, SurfaceOf(draw), SurfaceOf(read), context_)) {
            core::LogError(
                "Filament on EGL: eglMakeCurrent on its thread failed (EGL error 0x{:x})",
                eglGetError());
        }
    }
    void commit(SwapChain* swap_chain) noexcept override {
        eglSwapBuffers(display_, SurfaceOf(swap_chain));
    }
    void setPresentationTime(int64_t) noexcept override {}

    // Filament asks for a platform fence only for a hard fence (FEngine's private
    // createFence), which neither Filament's public API nor Open3D makes; without
    // canCreateFence its timer queries stay off platform fences.
    bool canCreateFence() noexcept override { return false; }
    Fence* createFence() noexcept override { return nullptr; }
    void destroyFence(Fence*) noexcept override {}
    filament::backend::FenceStatus waitFence(Fence*, uint64_t) noexcept override {
        return filament::backend::FenceStatus::ERROR;
    }
    // No external streams or external texture storage (Android's); Open3D imports textures
    // by GL name instead.
    Stream* createStream(void*) noexcept override { return nullptr; }
    void destroyStream(Stream*) noexcept override {}
    void attach(Stream*, intptr_t) noexcept override {}
    void detach(Stream*) noexcept override {}
    void updateTexImage(Stream*, int64_t*) noexcept override {}
    ExternalTexture* createExternalTextureStorage() noexcept override { return nullptr; }
    void reallocateExternalStorage(ExternalTexture*, uint32_t, uint32_t,
                                   filament::backend::TextureFormat) noexcept override {}
    void destroyExternalTextureStorage(ExternalTexture*) noexcept override {}

private:
    struct Surface : SwapChain {
        explicit Surface(EGLSurface s) : surface(s) {}
        EGLSurface surface;
    };
    EGLSurface SurfaceOf(SwapChain* swap_chain) const {
        auto* surface = static_cast<Surface*>(swap_chain);
        return surface && surface->surface != EGL_NO_SURFACE ? surface->surface : pbuffer_;
    }

    EGLDisplay display_;
    EGLConfig config_;
    EGLContext shared_;
    EGLContext context_ = EGL_NO_CONTEXT;
    EGLSurface pbuffer_ = EGL_NO_SURFACE;
};

}  // namespace

EglContext::EglContext() {
    std::string tried;
    display_ = OpenDisplay(&description_, &tried);
    if (display_ == EGL_NO_DISPLAY) {
        core::ThrowError("EGL: no display could be initialized (tried {})", tried);
    }
    try {
        config_ = ChooseConfig(display_);
        if (config_ == nullptr) {
            core::ThrowError("EGL: {} has no RGB8 pbuffer configuration for OpenGL", description_);
        }
        context_ = CreateContext(display_, config_, EGL_NO_CONTEXT);
        if (context_ == EGL_NO_CONTEXT) {
            core::ThrowError("EGL: {} gives no OpenGL 4.5 core context (EGL error 0x{:x})",
                             description_, eglGetError());
        }
        surface_ = CreatePbuffer(display_, config_, 16, 16);
        MakeCurrent();
    } catch (...) {
        Release();
        throw;
    }
}

EglContext::~EglContext() { Release(); }

void EglContext::Release() {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (surface_ != EGL_NO_SURFACE) eglDestroySurface(display_, surface_);
    if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
    // The display stays initialized: EGL displays are per process and another engine (or
    // Filament's thread of this one, until it ends) may still use it.
}

void EglContext::MakeCurrent() const {
    eglBindAPI(EGL_OPENGL_API);
    if (!eglMakeCurrent(display_, surface_, surface_, context_)) {
        core::ThrowError("EGL: eglMakeCurrent failed (EGL error 0x{:x})", eglGetError());
    }
}

void EglContext::ReleaseCurrent() const {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

void* EglContext::GetProcAddress(const char* name) {
    return reinterpret_cast<void*>(eglGetProcAddress(name));
}

std::unique_ptr<filament::backend::Platform> CreateEglFilamentPlatform(const EglContext& context) {
    return std::make_unique<EglFilamentPlatform>(context);
}

std::string EglUnavailableReason() {
    try {
        EglContext context;
        context.ReleaseCurrent();
    } catch (const core::Open3DError& e) {
        return e.what();
    }
    return {};
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
