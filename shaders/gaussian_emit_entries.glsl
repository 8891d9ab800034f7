// One splat's tile entries in the exact order (tile keys) or the packed option (packed
// keys), shared by gaussian_emit.comp and gaussian_emit_chained.comp. Included after the
// `view`, `addresses`, `entry_keys` and `entry_values` declarations.
#ifndef OPEN3D_GAUSSIAN_EMIT_ENTRIES_GLSL
#define OPEN3D_GAUSSIAN_EMIT_ENTRIES_GLSL

// What an includer does with the tile keys it writes (the chained emit counts the tile
// sort's digits): a run of `count` consecutive tile keys from `first` (a row span, exact
// order only), and the filler key 0xFFFFFFFF; nothing by default.
#ifndef OPEN3D_EMIT_COUNT_RUN
#define OPEN3D_EMIT_COUNT_RUN(first, count)
#endif
#ifndef OPEN3D_EMIT_COUNT_FILLER
#define OPEN3D_EMIT_COUNT_FILLER()
#endif

// Writes (key, splat) for every tile of the splat's rectangle that TileRowSpan keeps, at
// entry slots [begin, end), in row-major tile order.
void EmitEntries(uint splat, uint begin, uint end, bool packed) {
    uint64_t projected = DeviceAddress(addresses.projected_lo, addresses.projected_hi);
    // Only the words of the members used are loaded: the rest of an unpacked record is dead.
    GaussianProjectedSplat record = LoadProjected(projected, splat);
    uint rect_min = record.rect_min, rect_max = record.rect_max;
    uint min_x = rect_min & 0xFFFFu, min_y = rect_min >> 16u;
    uint max_x = rect_max & 0xFFFFu, max_y = rect_max >> 16u;
    uint tiles_x = view.tiles_x;
    // The same float32 view depth the exact order sorts by (the projection's output).
    float norm_depth =
        packed ? PackedSortKeyDepth(record.depth, view.near_plane, view.packed_depth_scale) : 0.0;
    uint tile_bits = view.tile_bits;
    // When the count equals the rectangle's area the projection kept every tile of it (a
    // row's span is at most its width): every row is whole, no span is recomputed and the
    // record's centre and conic, the other half of its 64 bytes, are not read. The grid's
    // splats mostly cover one or two tiles.
    bool whole_rect = end - begin == (max_x - min_x) * (max_y - min_y);
    vec2 center = vec2(0.0);
    vec3 conic = vec3(0.0);
    float cull_t = 0.0;
    float det_q = 0.0;
    if (!whole_rect) {
        GaussianProjectedSplat shape = LoadProjected(projected, splat);  // loaded here only
        center = vec2(shape.center_x, shape.center_y);
        conic = shape.conic;
        cull_t = shape.cull_threshold;
        det_q = shape.det_q;
    }
    uint out_index = begin;
    for (uint ty = min_y; ty < max_y && out_index < end; ++ty) {
        uint span = whole_rect ? min_x | (max_x << 16u)
                               : TileRowSpan(center.x, center.y, conic.x, conic.y, conic.z,
                                             det_q, cull_t, ty, min_x, max_x);
        uint first = span & 0xFFFFu;
        uint last = min(span >> 16u, first + (end - out_index));
        for (uint tx = first; tx < last; ++tx) {
            uint tile = ty * tiles_x + tx;
            uint key = packed ? PackedSortKey(tile, norm_depth, tile_bits) : tile;
            entry_keys[out_index] = key;
            entry_values[out_index] = splat;
            ++out_index;
        }
        if (!packed && last > first) OPEN3D_EMIT_COUNT_RUN(ty * tiles_x + first, last - first);
    }
    // The projection counted these spans from the same stored values with the same
    // `precise` code, so this never runs; should a driver still round differently, the
    // slots get a key past every tile (tile bits cover tiles_x * tiles_y + 1 values), which
    // sorts last and is never composited, instead of leaving stale entries.
    for (; out_index < end; ++out_index) {
        entry_keys[out_index] = 0xFFFFFFFFu;
        entry_values[out_index] = splat;
        OPEN3D_EMIT_COUNT_FILLER();
    }
}

#endif  // OPEN3D_GAUSSIAN_EMIT_ENTRIES_GLSL
