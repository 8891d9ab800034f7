// libFuzzer harness for the paged splat file (t/io/SplatPageFile.h) and the streamer that walks
// it: any input is refused with an Open3DError or every page reads, and a few streaming steps
// over it stay within their pool and budget; no crash, no sanitizer report.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "open3d/core/Exception.h"
#include "open3d/t/io/SplatPageFile.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamer.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // The reader takes a path: one file per process in shared memory.
    static const std::string path =
        "/dev/shm/open3d_fuzz_" + std::to_string(::getpid()) + ".gspages";
    FILE* f = std::fopen(path.c_str(), "wb");
    if (f == nullptr) return 0;
    std::fwrite(data, 1, size, f);
    std::fclose(f);
    try {
        const open3d::t::io::SplatPageFile file(path);
        for (int64_t p = 0; p < file.NumPages(); ++p) {
            file.ReadNodes(p);
            file.ReadSplats(p);
        }
        if (file.PageCapacity() <= (int64_t(1) << 12)) {
            // What the reader accepts must be safe to stream: a pool of two slots, a cut
            // budget of 5, a camera 5 units back.
            open3d::visualization::rendering::SplatStreamer streamer(file, 2, 5);
            open3d::t::geometry::SplatCutView view;
            view.world_to_camera(2, 3) = 5.0;
            for (int step = 0; step < 4; ++step) {
                const auto s = streamer.Step(view, 1);
                if (s.cut_nodes > 5 || streamer.ResidentPages() > 2) __builtin_trap();
            }
        }
    } catch (const open3d::core::Open3DError&) {
    }
    std::remove(path.c_str());
    return 0;
}
