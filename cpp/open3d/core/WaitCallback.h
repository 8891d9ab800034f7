// A callback that long blocking waits on the GPU (Vulkan fences, Filament flushes) call about
// every kWaitCallbackPeriodMs while they wait, on the waiting thread. The viewer installs one
// for the duration of a frame to poll window events: a frame of seconds on a software device
// then no longer freezes the window. The callback must not throw (the waits are inside GPU
// submissions that must complete) and must not start GPU work of its own. Without a callback
// the waits block as before.
//
//   core::ScopedWaitCallback poll([] { glfwPollEvents(); });
#pragma once

#include <functional>

namespace open3d {
namespace core {

constexpr int kWaitCallbackPeriodMs = 10;

/// True when the calling thread has a callback installed.
bool HasWaitCallback();
/// Calls the calling thread's callback (nothing without one). Not re-entrant: a wait inside
/// the callback itself does not call it again.
void CallWaitCallback();

/// Installs `callback` for the calling thread until destroyed (then restores the previous).
class ScopedWaitCallback {
public:
    explicit ScopedWaitCallback(std::function<void()> callback);
    ~ScopedWaitCallback();
    ScopedWaitCallback(const ScopedWaitCallback&) = delete;
    ScopedWaitCallback& operator=(const ScopedWaitCallback&) = delete;

private:
    std::function<void()> previous_;
};

}  // namespace core
}  // namespace open3d
