// A small typed, contiguous, owning array for per-point attributes.
// Only what the splat data model needs: float32, uint8, uint16 (normalised depth) and int32
// (splat ID images), any rank, row-major.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace open3d {
namespace core {

enum class Dtype { Float32, UInt8, UInt16, Int32 };

/// Size of one element in bytes.
int64_t DtypeSize(Dtype dtype);
std::string DtypeName(Dtype dtype);

template <typename T>
constexpr Dtype DtypeOf();
template <>
constexpr Dtype DtypeOf<float>() {
    return Dtype::Float32;
}
template <>
constexpr Dtype DtypeOf<uint8_t>() {
    return Dtype::UInt8;
}
template <>
constexpr Dtype DtypeOf<uint16_t>() {
    return Dtype::UInt16;
}
template <>
constexpr Dtype DtypeOf<int32_t>() {
    return Dtype::Int32;
}

using SizeVector = std::vector<int64_t>;
std::string ShapeToString(const SizeVector& shape);

class Tensor {
public:
    /// An empty float32 tensor of shape {0}.
    Tensor();
    /// Zero-initialised tensor. Negative dimensions are an error.
    Tensor(const SizeVector& shape, Dtype dtype);
    /// Uninitialised tensor, for producers that write every element anyway (readers):
    /// skips a pass over memory that the first touch pays for again.
    static Tensor Empty(const SizeVector& shape, Dtype dtype);

    Tensor(const Tensor& other);
    Tensor& operator=(const Tensor& other);
    Tensor(Tensor&& other) noexcept = default;
    Tensor& operator=(Tensor&& other) noexcept = default;

    template <typename T>
    static Tensor FromVector(const std::vector<T>& values, const SizeVector& shape) {
        Tensor t(shape, DtypeOf<T>());
        t.CheckCount(static_cast<int64_t>(values.size()));
        std::copy(values.begin(), values.end(), t.Data<T>());
        return t;
    }

    Dtype GetDtype() const { return dtype_; }
    const SizeVector& GetShape() const { return shape_; }
    int64_t GetShape(int dim) const { return shape_.at(dim); }
    int64_t NumDims() const { return static_cast<int64_t>(shape_.size()); }
    int64_t NumElements() const;
    int64_t NumBytes() const { return num_bytes_; }

    /// Typed access; throws Open3DError when T does not match the dtype.
    template <typename T>
    T* Data() {
        CheckDtype(DtypeOf<T>());
        return reinterpret_cast<T*>(bytes_.get());
    }
    template <typename T>
    const T* Data() const {
        CheckDtype(DtypeOf<T>());
        return reinterpret_cast<const T*>(bytes_.get());
    }
    void* RawData() { return bytes_.get(); }
    const void* RawData() const { return bytes_.get(); }

    /// Same elements, new shape with the same element count.
    Tensor Reshape(const SizeVector& shape) const;

    /// Exact equality of dtype, shape and bytes.
    bool operator==(const Tensor& other) const;
    bool operator!=(const Tensor& other) const { return !(*this == other); }

private:
    void CheckDtype(Dtype dtype) const;
    void CheckCount(int64_t count) const;

    Dtype dtype_ = Dtype::Float32;
    SizeVector shape_{0};
    struct Free {
        void operator()(uint8_t* p) const;
    };
    // 64-byte aligned; buffers of 2 MiB and more ask for transparent huge pages, because
    // first-touch page faults dominate reading large scenes (see docs/environment-notes.md).
    std::unique_ptr<uint8_t[], Free> bytes_;
    int64_t num_bytes_ = 0;
};

}  // namespace core
}  // namespace open3d
