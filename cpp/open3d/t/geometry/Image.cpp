#include "open3d/t/geometry/Image.h"

#include <utility>

#include <algorithm>
#include <cmath>
#include <vector>

#include "open3d/core/Exception.h"

namespace open3d {
namespace t {
namespace geometry {

namespace {
void CheckShape(const core::SizeVector& shape) {
    if (shape.size() != 3 || shape[0] < 0 || shape[1] < 0 || shape[2] < 1 || shape[2] > 4) {
        core::ThrowError("Image needs shape [rows, cols, channels] with 1..4 channels, got {}",
                         core::ShapeToString(shape));
    }
}

// Reads element i of a tensor as double.
double ReadAsDouble(const core::Tensor& t, int64_t i) {
    switch (t.GetDtype()) {
        case core::Dtype::Float32:
            return t.Data<float>()[i];
        case core::Dtype::UInt8:
            return t.Data<uint8_t>()[i];
        case core::Dtype::UInt16:
            return t.Data<uint16_t>()[i];
        case core::Dtype::Int32:
            return t.Data<int32_t>()[i];
    }
    core::ThrowError("Image: unknown dtype {}", static_cast<int>(t.GetDtype()));
}
}  // namespace

Image::Image(int64_t rows, int64_t cols, int64_t channels, core::Dtype dtype) {
    CheckShape({rows, cols, channels});
    data_ = core::Tensor({rows, cols, channels}, dtype);
}

Image::Image(const core::Tensor& data) {
    CheckShape(data.GetShape());
    data_ = data;
}

Image::Image(core::Tensor&& data) {
    CheckShape(data.GetShape());
    data_ = std::move(data);
}

Image Image::ToUInt8(double scale) const {
    if (GetDtype() == core::Dtype::UInt8) return *this;
    Image out(GetRows(), GetCols(), GetChannels(), core::Dtype::UInt8);
    const float* src = Data<float>();
    uint8_t* dst = out.Data<uint8_t>();
    const int64_t n = data_.NumElements();
    for (int64_t i = 0; i < n; ++i) {
        const double v = std::clamp(static_cast<double>(src[i]) * scale, 0.0, 255.0);
        // NaN lands on 0 (clamp keeps NaN; the comparison below maps it to 0).
        dst[i] = v >= 0.0 ? static_cast<uint8_t>(std::lround(v)) : 0;
    }
    return out;
}

Image Image::ToFloat(double scale) const {
    Image out(GetRows(), GetCols(), GetChannels(), core::Dtype::Float32);
    float* dst = out.Data<float>();
    const int64_t n = data_.NumElements();
    for (int64_t i = 0; i < n; ++i) dst[i] = static_cast<float>(ReadAsDouble(data_, i) * scale);
    return out;
}

Image Image::SelectChannels(int64_t first, int64_t count) const {
    if (first < 0 || count < 1 || first + count > GetChannels()) {
        core::ThrowError("Image::SelectChannels: channels [{}, {}) outside 0..{}", first,
                         first + count, GetChannels());
    }
    Image out(GetRows(), GetCols(), count, GetDtype());
    const int64_t elem = core::DtypeSize(GetDtype());
    const auto* src = static_cast<const uint8_t*>(data_.RawData());
    auto* dst = static_cast<uint8_t*>(out.data_.RawData());
    const int64_t c_in = GetChannels();
    for (int64_t p = 0; p < NumPixels(); ++p) {
        std::copy_n(src + (p * c_in + first) * elem, count * elem, dst + p * count * elem);
    }
    return out;
}

Image Image::BoxDownsample(int64_t factor) const {
    if (factor < 1 || GetRows() % factor != 0 || GetCols() % factor != 0) {
        core::ThrowError("Image::BoxDownsample: a factor of {} does not divide {} x {} pixels",
                         factor, GetCols(), GetRows());
    }
    if (GetDtype() != core::Dtype::Float32) {
        core::ThrowError("Image::BoxDownsample: takes a Float32 image");
    }
    const int64_t rows = GetRows() / factor, cols = GetCols() / factor, c = GetChannels();
    Image out(rows, cols, c, core::Dtype::Float32);
    // Summed in double: a block of 8 x 8 float32 values keeps every bit of their mean.
    std::vector<double> sum(static_cast<size_t>(cols * c));
    for (int64_t y = 0; y < rows; ++y) {
        std::fill(sum.begin(), sum.end(), 0.0);
        for (int64_t dy = 0; dy < factor; ++dy) {
            const float* row = Data<float>() + (y * factor + dy) * GetCols() * c;
            for (int64_t x = 0; x < GetCols(); ++x) {
                for (int64_t k = 0; k < c; ++k) sum[(x / factor) * c + k] += row[x * c + k];
            }
        }
        const double scale = 1.0 / static_cast<double>(factor * factor);
        float* out_row = out.Data<float>() + y * cols * c;
        for (int64_t i = 0; i < cols * c; ++i) out_row[i] = static_cast<float>(sum[i] * scale);
    }
    return out;
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
