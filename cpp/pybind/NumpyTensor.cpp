#include "NumpyTensor.h"

#include <cstring>
#include <vector>

#include "open3d/core/Exception.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

namespace {

py::dtype NumpyDtype(core::Dtype dtype) {
    switch (dtype) {
        case core::Dtype::Float32:
            return py::dtype::of<float>();
        case core::Dtype::UInt8:
            return py::dtype::of<uint8_t>();
        case core::Dtype::UInt16:
            return py::dtype::of<uint16_t>();
    }
    return py::dtype::of<float>();
}

std::vector<py::ssize_t> Strides(const core::SizeVector& shape, int64_t item) {
    std::vector<py::ssize_t> strides(shape.size());
    py::ssize_t stride = item;
    for (size_t i = shape.size(); i-- > 0;) {
        strides[i] = stride;
        stride *= shape[i];
    }
    return strides;
}

}  // namespace

py::array ViewOfTensor(core::Tensor& tensor, py::object owner) {
    const core::SizeVector& shape = tensor.GetShape();
    return py::array(NumpyDtype(tensor.GetDtype()),
                     std::vector<py::ssize_t>(shape.begin(), shape.end()),
                     Strides(shape, core::DtypeSize(tensor.GetDtype())), tensor.RawData(), owner);
}

py::array ArrayFromImage(t::geometry::Image&& image, bool squeeze_channel) {
    // The pixels move into the keeper (Image holds its tensor by value and `image` is ours).
    auto* kept = new core::Tensor(std::move(const_cast<core::Tensor&>(image.AsTensor())));
    py::capsule owner(kept, [](void* p) { delete static_cast<core::Tensor*>(p); });
    core::SizeVector shape = kept->GetShape();
    if (squeeze_channel && shape.size() == 3 && shape[2] == 1) shape.pop_back();
    return py::array(NumpyDtype(kept->GetDtype()),
                     std::vector<py::ssize_t>(shape.begin(), shape.end()),
                     Strides(shape, core::DtypeSize(kept->GetDtype())), kept->RawData(), owner);
}

core::Tensor TensorFromArray(const py::array& array, const std::string& what) {
    core::Dtype dtype;
    if (py::isinstance<py::array_t<float>>(array)) {
        dtype = core::Dtype::Float32;
    } else if (py::isinstance<py::array_t<uint8_t>>(array)) {
        dtype = core::Dtype::UInt8;
    } else if (py::isinstance<py::array_t<uint16_t>>(array)) {
        dtype = core::Dtype::UInt16;
    } else {
        core::ThrowError("{}: dtype {} is not supported (float32, uint8 or uint16)", what,
                         std::string(py::str(array.dtype())));
    }
    core::SizeVector shape(array.shape(), array.shape() + array.ndim());
    core::Tensor tensor = core::Tensor::Empty(shape, dtype);
    // A C-contiguous copy of whatever layout came in (slices, transposes).
    const py::array contiguous = py::array::ensure(array, py::array::c_style);
    if (tensor.NumBytes() > 0) std::memcpy(tensor.RawData(), contiguous.data(), tensor.NumBytes());
    return tensor;
}

}  // namespace pybind
}  // namespace open3d
