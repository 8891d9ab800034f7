// libFuzzer harness for the PLY and .splat readers (OPEN3D_FUZZ_EXTENSION picks which).
// Any input must end in a cloud or an Open3DError: no crash, no sanitizer report, and no
// allocation beyond what the input size allows (libFuzzer's -rss_limit_mb catches that).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/t/io/PointCloudIO.h"

namespace {

std::string ScratchPath() {
    // One file per process in shared memory: the readers take a path.
    static const std::string path =
        "/dev/shm/open3d_fuzz_" + std::to_string(::getpid()) + OPEN3D_FUZZ_EXTENSION;
    return path;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    open3d::core::SetLogLevel(open3d::core::LogLevel::Error);  // warnings are expected
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = ScratchPath();
    FILE* f = std::fopen(path.c_str(), "wb");
    if (f == nullptr) return 0;
    std::fwrite(data, 1, size, f);
    std::fclose(f);
    for (bool drop : {false, true}) {
        open3d::t::geometry::PointCloud cloud;
        open3d::t::io::ReadPointCloudOptions options;
        options.drop_non_finite = drop;
        try {
            open3d::t::io::ReadPointCloud(path, cloud, options);
            if (cloud.NumPoints() > 0 && cloud.HasPointAttr("scale")) cloud.ValidateGaussianSplat();
        } catch (const open3d::core::Open3DError&) {
        }
    }
    std::remove(path.c_str());
    return 0;
}
