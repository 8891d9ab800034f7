// The tile-count scan's offsets, for the shaders that read them (the emit, the dispatch-args
// pass) and the scan itself. Included after the `view` and `scan[]` buffer declarations.
// The scan buffer holds level 0 (the N list slots), then the block sums of every level
// above (GaussianGeometryStage::GetStorageRequirements). The scan only goes up: each level is
// exclusive within its blocks of kScanBlockSize and the top level is whole, so a slot's
// offset is the sum of its value and its blocks' values on every level above, the sums a
// down-sweep would have added. That saves the down-sweep's dispatches for a few cached loads
// per read (docs/perf/h200.md).
#ifndef OPEN3D_GAUSSIAN_SCAN_OFFSET_GLSL
#define OPEN3D_GAUSSIAN_SCAN_OFFSET_GLSL

uint SatAdd(uint a, uint b) {
    return min(min(a, kScanSaturation) + min(b, kScanSaturation), kScanSaturation);
}

// Exclusive offset of list slot k (k below the scanned count).
uint ScanOffset(uint k) {
    uint count = max(view.num_splats, 1u);  // level 0's size, N
    uint offset = scan[k];
    uint base = 0u;
    for (uint level = 1u; level < kScanMaxLevels && count > kScanBlockSize; ++level) {
        base += count;
        count = (count + kScanBlockSize - 1u) / kScanBlockSize;
        k /= kScanBlockSize;
        offset = SatAdd(offset, scan[base + k]);
    }
    return offset;
}

#endif  // OPEN3D_GAUSSIAN_SCAN_OFFSET_GLSL
