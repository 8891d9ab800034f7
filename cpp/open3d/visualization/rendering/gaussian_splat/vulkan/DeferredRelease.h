// Resources kept alive until the GPU is done with them: with frames in flight, a scene
// replaced (or a mask, or a precision change) while earlier submissions still read the old
// buffers must not free them. Each retired resource is keyed by the serial of the last
// submission that may use it and released once every submission up to it has completed.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <utility>

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

class DeferredReleaseQueue {
public:
    /// Keeps `resource` (any movable object: Buffer, Image, ...) until Release(serial) or a
    /// later serial.
    template <typename T>
    void Defer(uint64_t serial, T&& resource) {
        items_.push_back({serial, std::make_shared<std::decay_t<T>>(std::forward<T>(resource))});
    }
    /// Destroys what every submission up to and including `completed_serial` was the last
    /// user of. Serials are handed out in order, so the queue is released from its front.
    void Release(uint64_t completed_serial) {
        while (!items_.empty() && items_.front().first <= completed_serial) items_.pop_front();
    }
    /// Destroys everything (the caller waited for the device).
    void Clear() { items_.clear(); }
    size_t Pending() const { return items_.size(); }

private:
    std::deque<std::pair<uint64_t, std::shared_ptr<void>>> items_;
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
