#include "open3d/core/Progress.h"

#include <algorithm>
#include <utility>

namespace open3d {
namespace core {

namespace {
thread_local ProgressCallback t_callback;
}  // namespace

bool HasProgressCallback() { return static_cast<bool>(t_callback); }

void ReportProgress(const char* stage, double fraction) {
    if (t_callback) t_callback(stage, std::clamp(fraction, 0.0, 1.0));
}

ScopedProgressCallback::ScopedProgressCallback(ProgressCallback callback)
    : previous_(std::exchange(t_callback, std::move(callback))) {}

ScopedProgressCallback::~ScopedProgressCallback() { t_callback = std::move(previous_); }

}  // namespace core
}  // namespace open3d
