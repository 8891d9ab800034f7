// The q-quantile of a sample by nearest rank (the value at index round(q (n - 1)) of the sorted
// values): what the benchmarks and the viewer's frame statistics report as medians and
// percentiles.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "open3d/core/Exception.h"

namespace open3d {
namespace core {

/// q in [0, 1]; throws for an empty sample.
inline double Percentile(std::vector<double> values, double q) {
    if (values.empty()) ThrowError("Percentile of no values");
    std::sort(values.begin(), values.end());
    const size_t i =
        std::min(values.size() - 1, static_cast<size_t>(q * double(values.size() - 1) + 0.5));
    return values[i];
}

}  // namespace core
}  // namespace open3d
