// Work run on Filament's driver thread at a point of its command stream (docs/filament.md
// "GPU-side hand-over"). Filament 1.9's OpenGL driver makes its GL calls on its own thread
// with its own context; a GL command that must be ordered with Filament's (a semaphore wait
// before its compose view samples the splat image, a signal after its mesh view) has to be
// issued there, between them. Filament's public API has no such callback, but its command
// stream has one: CommandStream::queueCommand(std::function<void()>), exported from
// libfilament_backend 1.9.25, which Filament's own soft fences use. The engine's stream sits
// at a fixed place inside Filament's private FEngine; DriverThreadHook finds it there and
// checks that it is one (its driver is Filament's OpenGLDriver) before anything is queued.
// It allocates no Filament handle and asks the platform for nothing, so it works on both
// platforms, EGL and GLX.
#pragma once

#include <functional>
#include <string>

namespace filament {
class Engine;
namespace backend {
class CommandStream;
}  // namespace backend
}  // namespace filament

namespace open3d {
namespace visualization {
namespace rendering {

/// The command stream of one engine, located once after Engine::create.
class DriverThreadHook {
public:
    /// Locates `engine`'s command stream; when it is not where Filament 1.9.25 keeps it, or
    /// its driver is not Filament's OpenGL driver, the hook is unavailable and Why() says so.
    explicit DriverThreadHook(filament::Engine& engine);

    bool Available() const { return stream_ != nullptr; }
    /// Why the hook is unavailable ("" when it is available).
    const std::string& Why() const { return why_; }

    /// Queues `action` after every command issued to the engine so far and before every
    /// later one; it runs on the driver thread, Filament's GL context current, once
    /// Filament's stream is flushed (Engine::flush, flushAndWait or the next frame). Call it
    /// from the engine's thread, like every Filament call. False (and nothing queued) when
    /// the hook is unavailable.
    bool Run(std::function<void()> action) const;

private:
    filament::backend::CommandStream* stream_ = nullptr;
    std::string why_;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
