// The CPU mirror of the GPU level-of-detail cut (shaders/gaussian_lod_cut.comp; docs/lod.md
// "The cut on the GPU"), in double precision: the reference its tests compare with. Not
// t::geometry::CutSplatHierarchy's greedy cut: this one opens every node whose effective
// size bucket lies above one threshold, which a GPU finds with a histogram.
#pragma once

#include <cstdint>
#include <vector>

#include "GaussianSplatLodContract.h"
#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/SplatHierarchy.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

/// Size bucket (GaussianSplatLodContract.h) of a sphere of `radius` about `center` (world):
/// 0 when it lies wholly behind the camera or outside its frustum with the guard band.
uint32_t LodSizeBucket(const camera::PinholeCamera& camera, const double center[3], double radius);

struct LodCutResult {
    std::vector<int64_t> nodes;  ///< the cut, ascending node ids
    uint32_t threshold = 0;      ///< bucket opened above, or shader::kLodOpenAll
};

/// The cut of at most `budget` nodes (0: no limit, the leaves) the GPU chooses for `camera`:
/// each inner node's effective bucket is the smallest on its path to the root; the lowest
/// threshold t whose cut (1 + what opening every node above t adds) fits is taken, every
/// node above it opens. Everything in view and outside opens when the whole tree fits.
LodCutResult CutLikeGpu(const t::geometry::SplatHierarchy& hierarchy,
                        const camera::PinholeCamera& camera, uint64_t budget);

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
