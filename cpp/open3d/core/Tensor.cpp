#include "open3d/core/Tensor.h"

#include <fmt/format.h>

#include <sys/mman.h>

#include <cstdlib>
#include <cstring>

#include "open3d/core/Exception.h"

namespace open3d {
namespace core {

int64_t DtypeSize(Dtype dtype) {
    switch (dtype) {
        case Dtype::Float32:
            return 4;
        case Dtype::UInt8:
            return 1;
        case Dtype::UInt16:
            return 2;
        case Dtype::Int32:
            return 4;
    }
    ThrowError("Tensor: unknown dtype {}", static_cast<int>(dtype));
}

std::string DtypeName(Dtype dtype) {
    switch (dtype) {
        case Dtype::Float32:
            return "Float32";
        case Dtype::UInt8:
            return "UInt8";
        case Dtype::UInt16:
            return "UInt16";
        case Dtype::Int32:
            return "Int32";
    }
    ThrowError("Tensor: unknown dtype {}", static_cast<int>(dtype));
}

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

namespace {

constexpr size_t kHugePage = size_t(2) << 20;

uint8_t* Allocate(int64_t num_bytes) {
    if (num_bytes == 0) return nullptr;
    const size_t align = num_bytes >= int64_t(kHugePage) ? kHugePage : 64;
    const size_t size = (size_t(num_bytes) + align - 1) / align * align;
    void* p = std::aligned_alloc(align, size);
    if (p == nullptr) ThrowError("Tensor: cannot allocate {} bytes", num_bytes);
    // A 4 KiB page fault costs ~10 us on our VMs; a 2 MiB one amortises that 512 times.
    if (align == kHugePage) madvise(p, size, MADV_HUGEPAGE);
    return static_cast<uint8_t*>(p);
}

}  // namespace

void Tensor::Free::operator()(uint8_t* p) const { std::free(p); }

Tensor::Tensor() = default;

Tensor::Tensor(const SizeVector& shape, Dtype dtype) : Tensor(Empty(shape, dtype)) {
    if (num_bytes_ > 0) std::memset(bytes_.get(), 0, num_bytes_);
}

Tensor Tensor::Empty(const SizeVector& shape, Dtype dtype) {
    Tensor t;
    t.dtype_ = dtype;
    t.shape_ = shape;
    t.num_bytes_ = CountElements(shape) * DtypeSize(dtype);
    t.bytes_.reset(Allocate(t.num_bytes_));
    return t;
}

Tensor::Tensor(const Tensor& other)
    : dtype_(other.dtype_),
      shape_(other.shape_),
      bytes_(Allocate(other.num_bytes_)),
      num_bytes_(other.num_bytes_) {
    if (num_bytes_ > 0) std::memcpy(bytes_.get(), other.bytes_.get(), num_bytes_);
}

Tensor& Tensor::operator=(const Tensor& other) {
    if (this != &other) *this = Tensor(other);
    return *this;
}

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
    return dtype_ == other.dtype_ && shape_ == other.shape_ &&
           (num_bytes_ == 0 || std::memcmp(bytes_.get(), other.bytes_.get(), num_bytes_) == 0);
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
