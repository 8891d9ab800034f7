// What the streaming tests size their pools from: the pages a view needs on its own.
#pragma once

#include <cstdint>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/io/SplatPageFile.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamer.h"

namespace open3d {
namespace tests {

/// The pages a streamer with room for every page holds once `cam`'s cut (the budget: every
/// leaf) wants nothing more.
inline int64_t PagesTheViewNeeds(const t::io::SplatPageFile& file,
                                 const camera::PinholeCamera& cam) {
    visualization::rendering::SplatStreamer unlimited(file, file.NumPages(), file.NumLeaves());
    while (unlimited.Step(visualization::rendering::SplatCutViewOf(cam), 64).pages_wanted > 0) {
    }
    return unlimited.ResidentPages();
}

}  // namespace tests
}  // namespace open3d
