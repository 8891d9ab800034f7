// libFuzzer harness for the level-of-detail hierarchy reader: any input ends in a hierarchy
// whose every cut covers each leaf once, or in an Open3DError; no crash, no sanitizer report.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "open3d/core/Exception.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/SplatHierarchyIO.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // The reader takes a path: one file per process in shared memory.
    static const std::string path = "/dev/shm/open3d_fuzz_" + std::to_string(::getpid()) + ".lod";
    FILE* f = std::fopen(path.c_str(), "wb");
    if (f == nullptr) return 0;
    std::fwrite(data, 1, size, f);
    std::fclose(f);
    try {
        const open3d::t::geometry::SplatHierarchy h = open3d::t::io::ReadSplatHierarchy(path);
        // What a reader hands out must be safe to cut.
        open3d::t::geometry::SplatCutView view;
        view.world_to_camera(2, 3) = 5.0;
        const auto cut = open3d::t::geometry::CutSplatHierarchy(h, view, 16);
        if (cut.empty() || cut.size() > 16) __builtin_trap();
    } catch (const open3d::core::Open3DError&) {
    }
    std::remove(path.c_str());
    return 0;
}
