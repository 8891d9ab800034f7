// Wall-clock timing for logs, stats and benchmarks.
#pragma once

#include <chrono>

namespace open3d {
namespace core {

/// Milliseconds elapsed since `start` (steady clock).
inline double MillisecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

}  // namespace core
}  // namespace open3d
