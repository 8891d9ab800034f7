// The apps' last line of defence: whatever a run throws becomes "<tool>: error: ..." and exit
// status 1, never an abort (std::bad_alloc from a size a file claimed included).
#pragma once

#include <cstdio>
#include <exception>
#include <new>

namespace open3d {
namespace apps {

template <typename Run>
int RunReportingErrors(const char* tool, Run&& run) {
    try {
        return run();
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr,
                     "%s: error: out of memory (std::bad_alloc): the scene or the images asked "
                     "for need more host memory than this machine gives (docs/memory.md)\n",
                     tool);
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: error: %s\n", tool, e.what());
        return 1;
    }
}

}  // namespace apps
}  // namespace open3d
