// A parallel-for over index ranges on plain std::threads (no pool: calls are coarse).
#pragma once

#include <cstdint>
#include <functional>

namespace open3d {
namespace core {

/// Number of worker threads ParallelFor uses: hardware concurrency, at least 2,
/// overridable with the environment variable OPEN3D_NUM_THREADS.
int GetNumThreads();

/// Calls body(begin, end) on disjoint chunks covering [0, n). Chunks are at least
/// min_chunk long, so tiny loops run on the calling thread. Exceptions thrown by a
/// chunk are rethrown on the calling thread after all chunks finish.
void ParallelForRange(int64_t n, const std::function<void(int64_t, int64_t)>& body,
                      int64_t min_chunk = 1024);

/// Calls body(i) for every i in [0, n) in parallel.
template <typename F>
void ParallelFor(int64_t n, F&& body, int64_t min_chunk = 1024) {
    ParallelForRange(
        n,
        [&body](int64_t begin, int64_t end) {
            for (int64_t i = begin; i < end; ++i) body(i);
        },
        min_chunk);
}

}  // namespace core
}  // namespace open3d
