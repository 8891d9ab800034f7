#include "open3d/visualization/rendering/filament/FilamentEngine.h"

#include <GLFW/glfw3.h>
#define GLFW_EXPOSE_NATIVE_X11
#define GLFW_EXPOSE_NATIVE_GLX
#include <GLFW/glfw3native.h>
#include <filament/Engine.h>
#include <filament/Fence.h>

#include <chrono>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/WaitCallback.h"
#include "open3d/visualization/rendering/filament/EglPlatform.h"
#include "open3d/visualization/rendering/filament/FilamentDriverThread.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanDriversLoaded.h"

namespace open3d {
namespace visualization {
namespace rendering {

namespace {

constexpr const char* kRunUnderXvfb =
    "Filament 1.9's OpenGL backend needs an X server (GLX); on a machine without a display "
    "run the program under Xvfb, e.g. `xvfb-run -a -s \"-screen 0 1280x1024x24\" <command>`";

// GLFW is initialised once per process and terminated with the last engine.
std::mutex glfw_mutex;
int glfw_users = 0;
std::string glfw_error;

void OnGlfwError(int code, const char* description) {
    glfw_error = fmt::format("GLFW error 0x{:x}: {}", code, description);
}

bool AcquireGlfw(std::string* why) {
    std::lock_guard<std::mutex> lock(glfw_mutex);
    if (glfw_users > 0) {
        ++glfw_users;
        return true;
    }
    const char* display = std::getenv("DISPLAY");
    if (display == nullptr || display[0] == '\0') {
        *why = fmt::format("DISPLAY is not set. {}", kRunUnderXvfb);
        return false;
    }
    glfwSetErrorCallback(OnGlfwError);
    // An X server that is there can still refuse a connection for a moment (seen with Xvfb
    // while other test processes connect at once): try a few times before giving up.
    constexpr int kAttempts = 5;
    for (int attempt = 1;; ++attempt) {
        glfw_error.clear();
        if (glfwInit()) break;
        if (attempt == kAttempts) {
            *why = fmt::format("cannot open X display '{}' ({}; {} attempts). {}", display,
                               glfw_error, kAttempts, kRunUnderXvfb);
            return false;
        }
        core::LogWarning("cannot open X display '{}' ({}); trying again", display, glfw_error);
        std::this_thread::sleep_for(std::chrono::milliseconds(200 * attempt));
    }
    ++glfw_users;
    return true;
}

void ReleaseGlfw() {
    std::lock_guard<std::mutex> lock(glfw_mutex);
    if (--glfw_users == 0) glfwTerminate();
}

void* GlfwProc(const char* name) { return reinterpret_cast<void*>(glfwGetProcAddress(name)); }

}  // namespace

GlPlatform ResolveGlPlatform(GlPlatform platform) {
    if (platform != GlPlatform::kAuto) return platform;
    if (const char* env = std::getenv("OPEN3D_FILAMENT_PLATFORM"); env && env[0] != '\0') {
        const std::string value = env;
        if (value == "glx") return GlPlatform::kGlx;
        if (value == "egl") return GlPlatform::kEgl;
        if (value != "auto") {
            core::ThrowError("OPEN3D_FILAMENT_PLATFORM must be auto, glx or egl, got '{}'", value);
        }
    }
    const char* display = std::getenv("DISPLAY");
    return display != nullptr && display[0] != '\0' ? GlPlatform::kGlx : GlPlatform::kEgl;
}

std::string FilamentUnavailableReason(GlPlatform platform) {
    std::string why;
    try {
        platform = ResolveGlPlatform(platform);
    } catch (const core::Open3DError& e) {
        return e.what();
    }
    if (platform == GlPlatform::kEgl) {
        why = EglUnavailableReason();
        return why.empty() ? why
                           : fmt::format("{} (without an X server Filament runs on EGL)", why);
    }
    if (!AcquireGlfw(&why)) return why;
    ReleaseGlfw();
    return {};
}

FilamentEngine::FilamentEngine(GlPlatform platform) : platform_(ResolveGlPlatform(platform)) {
    if (platform_ == GlPlatform::kEgl) {
        StartEgl();
    } else {
        StartGlx();
    }
    driver_hook_ = std::make_unique<DriverThreadHook>(*engine_);
}

void FilamentEngine::StartEgl() {
    vulkan_drivers_ = vulkan::KeepVulkanDriversLoaded();
    egl_ = std::make_unique<EglContext>();
    gl_ = GlFunctions::Load(&EglContext::GetProcAddress);
    filament_platform_ = CreateEglFilamentPlatform(*egl_);
    engine_ = filament::Engine::create(filament::Engine::Backend::OPENGL, filament_platform_.get(),
                                       egl_->NativeContext());
    if (engine_ == nullptr) {
        core::ThrowError("Filament: Engine::create(OPENGL) on {} failed", egl_->Description());
    }
    egl_->MakeCurrent();
}

std::string FilamentEngine::DescribePlatform() const {
    return egl_ ? "EGL: " + egl_->Description() : std::string("GLX");
}

void FilamentEngine::StartGlx() {
    std::string why;
    if (!AcquireGlfw(&why)) core::ThrowError("Filament: {}", why);
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
    // llvmpipe offers 4.5 core, not 4.6 (ENVIRONMENT.md).
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_ALPHA_BITS, 0);
    glfw_error.clear();
    window_ = glfwCreateWindow(16, 16, "open3d-filament-context", nullptr, nullptr);
    if (window_ == nullptr) {
        ReleaseGlfw();
        core::ThrowError("Filament: GLFW could not create a hidden OpenGL 4.5 core context ({})",
                         glfw_error);
    }
    glfwMakeContextCurrent(window_);
    try {
        gl_ = GlFunctions::Load(&GlfwProc);
    } catch (...) {
        glfwDestroyWindow(window_);
        ReleaseGlfw();
        throw;
    }
    void* shared_context = glfwGetGLXContext(window_);
    engine_ = filament::Engine::create(filament::Engine::Backend::OPENGL, nullptr, shared_context);
    if (engine_ == nullptr) {
        glfwDestroyWindow(window_);
        ReleaseGlfw();
        core::ThrowError("Filament: Engine::create(OPENGL) failed");
    }
    // Engine creation may leave another context current on this thread.
    glfwMakeContextCurrent(window_);
}

FilamentEngine::~FilamentEngine() {
    filament::Engine::destroy(&engine_);
    filament_platform_.reset();
    if (egl_) {
        egl_.reset();
        return;
    }
    glfwMakeContextCurrent(nullptr);
    glfwDestroyWindow(window_);
    ReleaseGlfw();
}

void FilamentEngine::MakeContextCurrent() const {
    if (egl_) {
        egl_->MakeCurrent();
    } else {
        glfwMakeContextCurrent(window_);
    }
}

HeadlessSwapChain::HeadlessSwapChain(const FilamentEngine& engine, int width, int height)
    : engine_(engine),
      swap_chain_(engine.GetEngine().createSwapChain(uint32_t(width), uint32_t(height), 0)) {
    if (swap_chain_ == nullptr) {
        core::ThrowError("Filament: no headless swap chain of {} x {}", width, height);
    }
}

HeadlessSwapChain::~HeadlessSwapChain() { engine_.GetEngine().destroy(swap_chain_); }

void FilamentEngine::Flush() const {
    // Filament 1.9 has no Engine::flush; a fence's flushing wait with no time flushes alone.
    filament::Fence* fence = engine_->createFence();
    fence->wait(filament::Fence::Mode::FLUSH, 0);
    engine_->destroy(fence);
}

bool FilamentEngine::RunOnDriverThread(std::function<void()> action) const {
    return driver_hook_->Run(std::move(action));
}

bool FilamentEngine::CanRunOnDriverThread() const { return driver_hook_->Available(); }

std::string FilamentEngine::DriverThreadUnavailableReason() const { return driver_hook_->Why(); }

void FilamentEngine::FlushAndWait() const {
    if (core::HasWaitCallback()) {
        // A fence after the work so far, waited for in slices; flushAndWait then returns at
        // once and runs the completion callbacks as it always does.
        filament::Fence* fence = engine_->createFence();
        constexpr uint64_t kSliceNs = uint64_t(core::kWaitCallbackPeriodMs) * 1000000u;
        while (fence->wait(filament::Fence::Mode::FLUSH, kSliceNs) ==
               filament::backend::FenceStatus::TIMEOUT_EXPIRED) {
            core::CallWaitCallback();
        }
        engine_->destroy(fence);
    }
    engine_->flushAndWait();
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
