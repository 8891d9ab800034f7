#include "open3d/core/Tensor.h"

#include <fmt/format.h>

#include <cstring>

#include "open3d/core/Exception.h"

namespace open3d {
namespace core {

int64_t DtypeSize(Dtype dtype) { return dtype == Dtype::Float32 ? 4 : 1; }

std::string DtypeName(Dtype dtype) { return dtype == Dtype::Float32 ? "Float32" : "UInt8"; }

std::string ShapeToString(const SizeVector& shape) {
    return fmt::format("[{}]", fmt::join(shape, ", "));
}

static int64_t CountElements(const SizeVector& shape) {
    int64_t n = 1;
    for (int64_t d : shape) {
        if (d < 0) ThrowError("Tensor: negative dimension in shape {}", ShapeToString(shape));
        n *= d;
    }
    return n;
}

Tensor::Tensor() = default;

Tensor::Tensor(const SizeVector& shape, Dtype dtype)
    : dtype_(dtype), shape_(shape), bytes_(CountElements(shape) * DtypeSize(dtype), 0) {}

int64_t Tensor::NumElements() const { return CountElements(shape_); }

Tensor Tensor::Reshape(const SizeVector& shape) const {
    if (CountElements(shape) != NumElements()) {
        ThrowError("Tensor::Reshape: cannot reshape {} to {}", ShapeToString(shape_),
                   ShapeToString(shape));
    }
    Tensor t = *this;
    t.shape_ = shape;
    return t;
}

bool Tensor::operator==(const Tensor& other) const {
    return dtype_ == other.dtype_ && shape_ == other.shape_ && bytes_ == other.bytes_;
}

void Tensor::CheckDtype(Dtype dtype) const {
    if (dtype != dtype_) {
        ThrowError("Tensor: accessed as {} but holds {}", DtypeName(dtype), DtypeName(dtype_));
    }
}

void Tensor::CheckCount(int64_t count) const {
    if (count != NumElements()) {
        ThrowError("Tensor: {} values given for shape {}", count, ShapeToString(shape_));
    }
}

}  // namespace core
}  // namespace open3d
