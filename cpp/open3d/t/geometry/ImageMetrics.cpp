#include "open3d/t/geometry/ImageMetrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "open3d/core/Exception.h"

namespace open3d {
namespace t {
namespace geometry {

namespace {
void CheckSame(const Image& a, const Image& b) {
    if (a.AsTensor().GetShape() != b.AsTensor().GetShape() || a.GetDtype() != b.GetDtype()) {
        core::ThrowError(
            "image metrics: images differ in shape or dtype ({} {} vs {} {})",
            core::ShapeToString(a.AsTensor().GetShape()), core::DtypeName(a.GetDtype()),
            core::ShapeToString(b.AsTensor().GetShape()), core::DtypeName(b.GetDtype()));
    }
}
}  // namespace

ImageErrorMetrics ComputeImageErrorMetrics(const Image& a, const Image& b, double peak,
                                           double threshold) {
    CheckSame(a, b);
    const Image fa = a.ToFloat();
    const Image fb = b.ToFloat();
    const float* pa = fa.Data<float>();
    const float* pb = fb.Data<float>();
    const int64_t channels = a.GetChannels();
    ImageErrorMetrics m;
    m.num_pixels = a.NumPixels();
    double sum_sq = 0.0, sum_abs = 0.0;
    int64_t over = 0;
    for (int64_t p = 0; p < m.num_pixels; ++p) {
        bool pixel_over = false;
        for (int64_t c = 0; c < channels; ++c) {
            const double d = std::abs(static_cast<double>(pa[p * channels + c]) -
                                      static_cast<double>(pb[p * channels + c]));
            sum_sq += d * d;
            sum_abs += d;
            m.max_abs_error = std::max(m.max_abs_error, d);
            pixel_over = pixel_over || d > threshold;
        }
        over += pixel_over ? 1 : 0;
    }
    const double n = static_cast<double>(m.num_pixels * channels);
    if (n == 0) {
        m.psnr_db = std::numeric_limits<double>::infinity();
        return m;
    }
    const double mse = sum_sq / n;
    m.psnr_db =
        mse == 0.0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(peak * peak / mse);
    m.mean_abs_error = sum_abs / n;
    m.fraction_over_threshold = static_cast<double>(over) / static_cast<double>(m.num_pixels);
    return m;
}

double ComputePSNR(const Image& a, const Image& b, double peak) {
    return ComputeImageErrorMetrics(a, b, peak, 0.0).psnr_db;
}
double ComputeMaxAbsError(const Image& a, const Image& b) {
    return ComputeImageErrorMetrics(a, b, 1.0, 0.0).max_abs_error;
}
double ComputeMeanAbsError(const Image& a, const Image& b) {
    return ComputeImageErrorMetrics(a, b, 1.0, 0.0).mean_abs_error;
}
double ComputeFractionOverThreshold(const Image& a, const Image& b, double threshold) {
    return ComputeImageErrorMetrics(a, b, 1.0, threshold).fraction_over_threshold;
}

Image ComputeAbsDifference(const Image& a, const Image& b) {
    CheckSame(a, b);
    const Image fa = a.ToFloat();
    const Image fb = b.ToFloat();
    Image out(a.GetRows(), a.GetCols(), a.GetChannels(), core::Dtype::Float32);
    const int64_t n = a.AsTensor().NumElements();
    for (int64_t i = 0; i < n; ++i) {
        out.Data<float>()[i] = std::abs(fa.Data<float>()[i] - fb.Data<float>()[i]);
    }
    return out;
}

double ComputeAbsErrorPercentile(const Image& a, const Image& b, double q) {
    if (!(q > 0.0 && q <= 1.0))
        core::ThrowError("ComputeAbsErrorPercentile: q = {} not in (0, 1]", q);
    const Image diff = ComputeAbsDifference(a, b);
    const int64_t n = diff.AsTensor().NumElements();
    if (n == 0) return 0.0;
    std::vector<float> values(diff.Data<float>(), diff.Data<float>() + n);
    const int64_t k = std::clamp<int64_t>(static_cast<int64_t>(std::ceil(q * n)) - 1, 0, n - 1);
    std::nth_element(values.begin(), values.begin() + k, values.end());
    return values[k];
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
