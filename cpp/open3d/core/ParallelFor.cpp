#include "open3d/core/ParallelFor.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace open3d {
namespace core {

int GetNumThreads() {
    static const int num_threads = [] {
        if (const char* env = std::getenv("OPEN3D_NUM_THREADS")) {
            const int n = std::atoi(env);
            if (n > 0) return n;
        }
        return std::max(2, static_cast<int>(std::thread::hardware_concurrency()));
    }();
    return num_threads;
}

void ParallelForRange(int64_t n, const std::function<void(int64_t, int64_t)>& body,
                      int64_t min_chunk) {
    if (n <= 0) return;
    min_chunk = std::max<int64_t>(1, min_chunk);
    const int64_t max_workers = (n + min_chunk - 1) / min_chunk;
    const int64_t workers = std::min<int64_t>(GetNumThreads(), max_workers);
    if (workers <= 1) {
        body(0, n);
        return;
    }
    // A few chunks per worker balance uneven work (e.g. busy image tiles).
    const int64_t num_chunks = std::min<int64_t>(max_workers, workers * 4);
    const int64_t chunk = (n + num_chunks - 1) / num_chunks;
    std::atomic<int64_t> next{0};
    std::exception_ptr error;
    std::mutex error_mutex;
    auto worker = [&]() {
        for (;;) {
            const int64_t c = next.fetch_add(1);
            const int64_t begin = c * chunk;
            if (begin >= n) return;
            try {
                body(begin, std::min(n, begin + chunk));
            } catch (...) {
                std::lock_guard<std::mutex> lock(error_mutex);
                if (!error) error = std::current_exception();
            }
        }
    };
    std::vector<std::thread> threads;
    threads.reserve(workers - 1);
    for (int64_t t = 1; t < workers; ++t) threads.emplace_back(worker);
    worker();
    for (auto& t : threads) t.join();
    if (error) std::rethrow_exception(error);
}

}  // namespace core
}  // namespace open3d
