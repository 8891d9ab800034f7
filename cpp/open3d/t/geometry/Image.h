// A 2D image on a core::Tensor of shape [rows, cols, channels], Float32, UInt8 or UInt16,
// row-major with interleaved channels (pixel (x, y) channel c at (y * cols + x) * C + c).
#pragma once

#include <cstdint>

#include "open3d/core/Tensor.h"

namespace open3d {
namespace t {
namespace geometry {

class Image {
public:
    /// An empty 0x0 Float32 image with one channel.
    Image() : Image(0, 0, 1, core::Dtype::Float32) {}
    /// Zero-initialised image. Throws for negative sizes or channels outside 1..4.
    Image(int64_t rows, int64_t cols, int64_t channels, core::Dtype dtype);
    /// Wraps a tensor of shape [rows, cols, channels] (copied).
    explicit Image(const core::Tensor& data);
    /// Takes the tensor's memory (no copy): for images filled through
    /// core::Tensor::Empty, which skips the zero fill.
    explicit Image(core::Tensor&& data);

    int64_t GetRows() const { return data_.GetShape(0); }
    int64_t GetCols() const { return data_.GetShape(1); }
    int64_t GetChannels() const { return data_.GetShape(2); }
    int64_t NumPixels() const { return GetRows() * GetCols(); }
    core::Dtype GetDtype() const { return data_.GetDtype(); }
    bool IsEmpty() const { return NumPixels() == 0; }

    /// The pixel buffer [rows, cols, channels].
    const core::Tensor& AsTensor() const { return data_; }

    template <typename T>
    T* Data() {
        return data_.Data<T>();
    }
    template <typename T>
    const T* Data() const {
        return data_.Data<T>();
    }
    /// Unchecked element access (the dtype is checked).
    template <typename T>
    T& At(int64_t y, int64_t x, int64_t c = 0) {
        return Data<T>()[(y * GetCols() + x) * GetChannels() + c];
    }
    template <typename T>
    const T& At(int64_t y, int64_t x, int64_t c = 0) const {
        return Data<T>()[(y * GetCols() + x) * GetChannels() + c];
    }

    /// UInt8 copy: round(clamp(v * scale, 0, 255)) per element (Float32 input), or a
    /// plain copy for UInt8 input.
    Image ToUInt8(double scale = 255.0) const;
    /// Float32 copy: v * scale per element.
    Image ToFloat(double scale = 1.0) const;
    /// Copy of channels [first, first + count).
    Image SelectChannels(int64_t first, int64_t count) const;
    /// Float32 image of rows / factor x cols / factor pixels, each the mean of a factor x
    /// factor block (a render at factor times the size, box-filtered to this one). Throws
    /// for a factor < 1, sizes it does not divide, or a dtype other than Float32.
    Image BoxDownsample(int64_t factor) const;

    bool operator==(const Image& other) const { return data_ == other.data_; }

private:
    core::Tensor data_;
};

}  // namespace geometry
}  // namespace t
}  // namespace open3d
