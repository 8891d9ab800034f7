#include "open3d/visualization/rendering/gaussian_splat/cpu/TileLists.h"

#include <algorithm>

#include <fmt/format.h>

#include "open3d/core/HostMemory.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

std::vector<uint32_t> SortVisibleByDepth(const std::vector<ProjectedSplat>& splats) {
    // The GPU's key: ProjectedSplat::sort_depth (float32, bit for bit the GPU's), ties by splat
    // index, so near-tied splats are ordered identically on both sides.
    struct Key {
        float depth;
        uint32_t index;
    };
    std::vector<Key> keys;
    keys.reserve(splats.size());
    for (size_t i = 0; i < splats.size(); ++i) {
        if (splats[i].IsVisible()) {
            keys.push_back({splats[i].sort_depth, static_cast<uint32_t>(i)});
        }
    }
    std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
        return a.depth < b.depth || (a.depth == b.depth && a.index < b.index);
    });
    std::vector<uint32_t> order(keys.size());
    for (size_t k = 0; k < keys.size(); ++k) order[k] = keys[k].index;
    return order;
}

TileLists BuildTileLists(const std::vector<ProjectedSplat>& splats, const TileGrid& grid,
                         const RenderConfig& config) {
    TileLists lists;
    lists.grid = grid;
    const std::vector<uint32_t> order = SortVisibleByDepth(splats);

    // Decide which splats emit entries, front to back, honouring the capacity limits.
    std::vector<uint32_t> emitting;
    emitting.reserve(order.size());
    uint64_t total = 0;
    for (uint32_t index : order) {
        const uint64_t tiles = static_cast<uint64_t>(splats[index].NumEntries());
        if (tiles > config.max_tiles_per_splat) {  // this splat alone emits nothing
            lists.error_flags |= kEntriesDropped;
            continue;
        }
        // The first splat that does not fit ends the list: the GPU keeps exactly this
        // depth-order prefix (a parallel scan cannot let later, smaller splats in).
        if (total + tiles > config.max_tile_entries_total) {
            lists.error_flags |= kEntriesDropped;
            break;
        }
        total += tiles;
        emitting.push_back(index);
    }

    // Counting sort by tile: stable, so each tile keeps the depth order.
    lists.offsets.assign(grid.NumTiles() + 1, 0);
    // Only the tiles the splat can change (ProjectedSplat::RowSpan, the GPU's culling).
    const auto for_each_tile = [&](const ProjectedSplat& s, auto&& visit) {
        for (int ty = s.rect_min_y; ty < s.rect_max_y; ++ty) {
            const auto [first, last] = s.RowSpan(ty);
            for (int tx = first; tx < last; ++tx)
                visit(static_cast<int64_t>(ty) * grid.tiles_x + tx);
        }
    };
    for (uint32_t index : emitting) {
        for_each_tile(splats[index], [&](int64_t tile) { ++lists.offsets[tile + 1]; });
    }
    for (size_t t = 1; t < lists.offsets.size(); ++t) lists.offsets[t] += lists.offsets[t - 1];
    std::vector<uint64_t> cursor(lists.offsets.begin(), lists.offsets.end() - 1);
    core::RequireHostMemory(total * sizeof(uint32_t),
                            fmt::format("cpu backend: {} tile entries", total),
                            "a lower resolution has fewer");
    lists.splat_indices.resize(total);
    for (uint32_t index : emitting) {
        for_each_tile(splats[index],
                      [&](int64_t tile) { lists.splat_indices[cursor[tile]++] = index; });
    }
    return lists;
}

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
