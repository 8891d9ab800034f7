// Internal to t/io: codebooks for the quantised formats (SOG): a 1D k-means over scalar
// values and a palette of coefficient vectors. Both are deterministic.
#pragma once

#include <cstdint>
#include <vector>

namespace open3d {
namespace t {
namespace io {

/// 1D k-means with 256 entries: exact (the sorted distinct values) when there are at most
/// 256 of them; otherwise Lloyd iterations over the sorted values from (weighted) quantile
/// seeds, minimising the sum of weight * squared error (weights empty: all 1). Returns the
/// codebook (ascending) and one label per value, the nearest entry.
std::vector<float> Quantise1D(const std::vector<float>& values, std::vector<uint8_t>& labels,
                              const std::vector<float>& weights = {}, int iterations = 32);

/// A palette of the n rows of `dims` floats at `rows` with one label per row: exact when
/// there are at most 65536 distinct rows, else k-means trained on a sample with a palette
/// size set by a compute budget.
std::vector<float> Palette(const float* rows, int64_t n, int dims, std::vector<int32_t>& labels);

}  // namespace io
}  // namespace t
}  // namespace open3d
