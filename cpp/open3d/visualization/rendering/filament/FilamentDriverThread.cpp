#include "open3d/visualization/rendering/filament/FilamentDriverThread.h"

#include <filament/Engine.h>
#include <filament/Fence.h>

#include <cstdint>
#include <utility>

// Filament 1.9.25's private engine, declared only as far as this file calls it:
// FEngine::createFence(FFence::Type) is exported from libfilament (Engine::createFence is a
// jump to it with Type 0, soft; Type 1, hard, goes through the driver's createFence and so
// through the platform's). The CMake check pins the version (docs/filament.md).
namespace filament {
class FFence : public Fence {
public:
    enum class Type : uint8_t { SOFT = 0, HARD = 1 };
};
class FEngine : public Engine {
public:
    FFence* createFence(FFence::Type type) noexcept;
};
}  // namespace filament

namespace open3d {
namespace visualization {
namespace rendering {

void DriverThreadQueue::Push(std::function<void()> action) {
    std::lock_guard<std::mutex> lock(mutex_);
    actions_.push_back(std::move(action));
}

void DriverThreadQueue::RunNext() {
    std::function<void()> action;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (actions_.empty()) return;
        action = std::move(actions_.front());
        actions_.pop_front();
    }
    action();
}

void RunOnDriverThread(filament::Engine& engine, DriverThreadQueue& queue,
                       std::function<void()> action) {
    queue.Push(std::move(action));
    // Every Engine is an FEngine; the fence is not waited for, only its creation matters.
    filament::FFence* fence =
        static_cast<filament::FEngine&>(engine).createFence(filament::FFence::Type::HARD);
    engine.destroy(fence);
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
