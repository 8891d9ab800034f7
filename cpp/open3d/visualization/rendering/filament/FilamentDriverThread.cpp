#include "open3d/visualization/rendering/filament/FilamentDriverThread.h"

#include <dlfcn.h>
#include <filament/Engine.h>

#include <cstdint>
#include <cstring>
#include <utility>

// Filament 1.9.25's private command stream, declared only as far as this file calls it.
// queueCommand places a CustomCommand holding the function in the stream's current buffer;
// the driver thread runs it in stream order (read from libfilament_backend.so.1.9.25).
namespace filament {
namespace backend {
class CommandStream {
public:
    void queueCommand(std::function<void()> command);
};
}  // namespace backend
}  // namespace filament

namespace open3d {
namespace visualization {
namespace rendering {
namespace {

// Where FEngine (every Engine is one) keeps its CommandStream in Debian's libfilament
// 1.9.25, whose first members are the dispatcher, the driver and the current buffer: FFence's
// constructor reads the driver at 0xa50 and queues its signal on the stream at 0xa48. The
// CMake check pins the version; the driver's vtable is checked below all the same.
constexpr std::size_t kCommandStreamOffset = 0xa48;
constexpr std::size_t kStreamDriverOffset = 0xa50;
constexpr const char* kOpenGLDriverVtable = "_ZTVN8filament12OpenGLDriverE";

}  // namespace

DriverThreadHook::DriverThreadHook(filament::Engine& engine) {
    auto* bytes = reinterpret_cast<unsigned char*>(&engine);
    void* driver = nullptr;
    std::memcpy(&driver, bytes + kStreamDriverOffset, sizeof(driver));
    if (driver == nullptr) {
        why_ = "Filament's command stream holds no driver where 1.9.25 keeps it";
        return;
    }
    // The object's vtable pointer is the vtable symbol plus two words (offset to top and
    // type info), whose name dladdr gives when the pointer lies inside libfilament_backend.
    void* vtable = nullptr;
    std::memcpy(&vtable, driver, sizeof(vtable));
    Dl_info info{};
    if (dladdr(vtable, &info) == 0 || info.dli_sname == nullptr ||
        std::strcmp(info.dli_sname, kOpenGLDriverVtable) != 0 ||
        static_cast<char*>(vtable) != static_cast<char*>(info.dli_saddr) + 2 * sizeof(void*)) {
        why_ = "the driver of Filament's command stream is not Filament 1.9.25's OpenGL driver";
        return;
    }
    stream_ = reinterpret_cast<filament::backend::CommandStream*>(bytes + kCommandStreamOffset);
}

bool DriverThreadHook::Run(std::function<void()> action) const {
    if (stream_ == nullptr) return false;
    stream_->queueCommand(std::move(action));
    return true;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
