// The tile count of a depth-sorted list slot, shared by the scan's gather
// (gaussian_scan.comp) and the chained emit (gaussian_emit_chained.comp). Included after the
// `view`, `counters`, `splat_indices` and `tile_counts` declarations.
#ifndef OPEN3D_GAUSSIAN_LIST_COUNT_GLSL
#define OPEN3D_GAUSSIAN_LIST_COUNT_GLSL

// Slot `index` of the depth-sorted list: its count from the list value, or through the splat
// index where the value holds the sentinel. The exact order walks all N slots; past the
// visible ones the list holds stale slots (the depth sort dropped the culled splats), which
// count nothing. A splat over max_tiles_per_splat counts 0 and flags the frame: it emits
// nothing.
uint ListSlotTileCount(uint index) {
    if (index >= counters.visible_count) return 0u;
    uint value = splat_indices[index];
    uint count = ListValueCount(value, view.num_splats);
    if (count == ListCountSentinel(view.num_splats)) {
        count = tile_counts[ListValueSplat(value, view.num_splats)];
    }
    if (count > view.max_tiles_per_splat) {
        atomicOr(counters.error_flags, kErrorEntriesDropped);
        return 0u;
    }
    return count;
}

#endif  // OPEN3D_GAUSSIAN_LIST_COUNT_GLSL
