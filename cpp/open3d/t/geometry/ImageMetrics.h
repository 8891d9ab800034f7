// Error metrics between two images of the same shape, for comparing renderers.
#pragma once

#include <cstdint>

#include "open3d/t/geometry/Image.h"

namespace open3d {
namespace t {
namespace geometry {

struct ImageErrorMetrics {
    /// 10 log10(peak^2 / MSE) over all elements; +infinity when the images are equal.
    double psnr_db = 0.0;
    double max_abs_error = 0.0;
    double mean_abs_error = 0.0;
    /// Share (0..1) of pixels with any channel differing by more than the threshold.
    double fraction_over_threshold = 0.0;
    int64_t num_pixels = 0;
};

/// Compares a and b element-wise (values as stored: UInt8 0..255, Float32 as is).
/// `peak` is the PSNR signal peak (1 for float images in 0..1, 255 for UInt8).
/// Throws core::Open3DError when the shapes or dtypes differ.
ImageErrorMetrics ComputeImageErrorMetrics(const Image& a, const Image& b, double peak,
                                           double threshold);

/// PSNR in dB (see ImageErrorMetrics::psnr_db).
double ComputePSNR(const Image& a, const Image& b, double peak);
double ComputeMaxAbsError(const Image& a, const Image& b);
double ComputeMeanAbsError(const Image& a, const Image& b);
/// Share of pixels with a channel differing by more than threshold.
double ComputeFractionOverThreshold(const Image& a, const Image& b, double threshold);

/// |a - b| per element, as Float32 (values as stored), for diff images.
Image ComputeAbsDifference(const Image& a, const Image& b);

/// The q-quantile (0 < q <= 1, nearest rank: element ceil(q n) - 1 in ascending order) of
/// |a - b| over all elements, e.g. q = 0.999 for the 99.9th percentile.
double ComputeAbsErrorPercentile(const Image& a, const Image& b, double q);

}  // namespace geometry
}  // namespace t
}  // namespace open3d
