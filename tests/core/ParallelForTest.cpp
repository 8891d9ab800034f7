#include "open3d/core/ParallelFor.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

namespace open3d {
namespace core {

TEST(ParallelFor, VisitsEveryIndexOnce) {
    for (int64_t n : {0, 1, 7, 1023, 1024, 1025, 100000}) {
        std::vector<std::atomic<int>> hits(n);
        ParallelFor(
            n, [&](int64_t i) { hits[i]++; }, 16);
        for (int64_t i = 0; i < n; ++i) ASSERT_EQ(hits[i].load(), 1) << "n=" << n << " i=" << i;
    }
}

TEST(ParallelFor, UsesAtLeastTwoThreads) { EXPECT_GE(GetNumThreads(), 2); }

TEST(ParallelFor, RethrowsWorkerException) {
    EXPECT_THROW(ParallelFor(
                     10000,
                     [](int64_t i) {
                         if (i == 7777) throw std::runtime_error("boom");
                     },
                     16),
                 std::runtime_error);
}

}  // namespace core
}  // namespace open3d
