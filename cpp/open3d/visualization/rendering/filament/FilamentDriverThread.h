// Work run on Filament's driver thread at a point of its command stream (docs/filament.md
// "GPU-side hand-over"). Filament 1.9's OpenGL driver makes its GL calls on its own thread
// with its own context; a GL command that must be ordered with Filament's (a semaphore wait
// before its compose view samples the splat image, a signal after its mesh view) has to be
// issued there, between them. Filament's public API has no such callback, but its driver
// asks the platform for a fence (OpenGLPlatform::createFence) on that thread, in stream
// order, for every "hard" fence, and only Open3D creates hard fences (Filament's own frame
// pacing uses syncs, flushAndWait soft fences: read from libfilament 1.9.25). So the EGL
// platform, which is Open3D's, runs the next queued action in each createFence.
#pragma once

#include <deque>
#include <functional>
#include <mutex>

namespace filament {
class Engine;
}  // namespace filament

namespace open3d {
namespace visualization {
namespace rendering {

/// The actions queued for the driver thread, in order; shared by the engine (which pushes)
/// and the EGL platform (which runs them).
class DriverThreadQueue {
public:
    void Push(std::function<void()> action);
    /// Runs the oldest action, if any (the platform's createFence, on the driver thread).
    void RunNext();

private:
    std::mutex mutex_;
    std::deque<std::function<void()>> actions_;
};

/// Pushes `action` and creates (and destroys) one hard fence on `engine`, whose platform
/// must run `queue` in createFence: the action then runs on the driver thread after every
/// command issued to the engine so far and before every later one, once Filament's stream
/// is flushed (Engine::flush, flushAndWait or the next frame).
void RunOnDriverThread(filament::Engine& engine, DriverThreadQueue& queue,
                       std::function<void()> action);

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
