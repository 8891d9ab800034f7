#include "open3d/core/WaitCallback.h"

#include <utility>

namespace open3d {
namespace core {

namespace {
thread_local std::function<void()> g_callback;
thread_local bool g_in_callback = false;
}  // namespace

bool HasWaitCallback() { return static_cast<bool>(g_callback) && !g_in_callback; }

void CallWaitCallback() {
    if (!HasWaitCallback()) return;
    struct Guard {
        Guard() { g_in_callback = true; }
        ~Guard() { g_in_callback = false; }
    } guard;
    g_callback();
}

ScopedWaitCallback::ScopedWaitCallback(std::function<void()> callback)
    : previous_(std::exchange(g_callback, std::move(callback))) {}

ScopedWaitCallback::~ScopedWaitCallback() { g_callback = std::move(previous_); }

}  // namespace core
}  // namespace open3d
