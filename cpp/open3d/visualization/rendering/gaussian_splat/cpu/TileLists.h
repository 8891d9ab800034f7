// Geometry stage, steps 2-3 of the CPU reference: one entry per (tile, splat) pair, sorted by
// tile, then by float32 depth, then by splat index (the order a stable radix sort of
// 3DGS's 64-bit (tile, depth) keys yields when entries are emitted in splat order).
#pragma once

#include <cstdint>
#include <vector>

#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

/// Per-tile front-to-back splat lists in CSR form: tile t (= ty * tiles_x + tx) composites
/// splat_indices[offsets[t] .. offsets[t + 1]).
struct TileLists {
    TileGrid grid;
    std::vector<uint64_t> offsets;        // [num_tiles + 1]
    std::vector<uint32_t> splat_indices;  // [num_entries]
    uint32_t error_flags = 0;             // kEntriesDropped when a capacity limit was hit

    int64_t NumEntries() const { return static_cast<int64_t>(splat_indices.size()); }
};

/// Visible splats in composite order: ascending float32(depth), ties by splat index.
std::vector<uint32_t> SortVisibleByDepth(const std::vector<ProjectedSplat>& splats);

/// Builds the sorted per-tile lists: each splat in the tiles of its rectangle that its
/// alpha >= 1/255 ellipse meets (ProjectedSplat::RowSpan). Limits: a splat with more than
/// config.max_tiles_per_splat such tiles emits nothing; once config.max_tile_entries_total
/// would be exceeded, farther splats emit nothing. Both set kEntriesDropped.
TileLists BuildTileLists(const std::vector<ProjectedSplat>& splats, const TileGrid& grid,
                         const RenderConfig& config);

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
