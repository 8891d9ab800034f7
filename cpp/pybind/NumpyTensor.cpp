#include "NumpyTensor.h"

#include <cmath>
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
        case core::Dtype::Int32:
            return py::dtype::of<int32_t>();
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

py::array ArrayForTensor(const py::handle& value, const std::string& what) {
    const py::module_ np = py::module_::import("numpy");
    py::array array;
    if (py::isinstance<py::array>(value)) {
        array = py::reinterpret_borrow<py::array>(value);
    } else {
        try {
            array = np.attr("asarray")(value);
        } catch (const py::error_already_set& e) {
            // Ragged lists and objects numpy cannot read; its own words say which.
            core::ThrowError("{}: not an array ({}: {})", what,
                             std::string(py::str(value.get_type().attr("__name__"))),
                             std::string(py::str(e.value())));
        }
    }
    if (py::isinstance<py::array_t<float>>(array) || py::isinstance<py::array_t<uint8_t>>(array) ||
        py::isinstance<py::array_t<uint16_t>>(array)) {
        return array;
    }
    const char kind = array.dtype().kind();
    const std::string dtype_name = py::str(array.dtype());
    if (kind == 'f') {
        // float64 values past float32's range would become infinities: refused by name
        // rather than turned into values that were never there.
        py::object converted;
        {
            py::object quiet = np.attr("errstate")(py::arg("over") = "ignore");
            quiet.attr("__enter__")();
            converted = array.attr("astype")(np.attr("float32"));
            quiet.attr("__exit__")(py::none(), py::none(), py::none());
        }
        const py::object lost = np.attr("logical_and")(
            np.attr("isfinite")(array), np.attr("logical_not")(np.attr("isfinite")(converted)));
        if (lost.attr("any")().cast<bool>()) {
            const py::tuple at =
                np.attr("unravel_index")(np.attr("argmax")(lost), array.attr("shape"));
            core::ThrowError(
                "{}: row {} holds {}, beyond float32's range (the library's float type)", what,
                at.empty() ? py::int_(0).cast<int64_t>() : at[0].cast<int64_t>(),
                std::string(py::repr(array[at])));
        }
        return converted;
    }
    if (kind == 'i' || kind == 'u') {
        // Integers from plain lists (int64) and label arrays: exact in float32 up to 2^24.
        const py::object converted = array.attr("astype")(np.attr("float32"));
        if (array.size() > 0 &&
            !np.attr("array_equal")(converted.attr("astype")(array.dtype()), array).cast<bool>()) {
            core::ThrowError(
                "{}: dtype {} holds integers that float32 cannot hold exactly (above 2^24); "
                "convert them yourself",
                what, dtype_name);
        }
        return converted;
    }
    core::ThrowError(
        "{}: dtype {} is not supported (float32, uint8 or uint16; other floating and integer "
        "dtypes are converted to float32)",
        what, dtype_name);
}

core::Tensor TensorFromArray(const py::handle& value, const std::string& what,
                             bool allow_non_finite) {
    const py::array array = ArrayForTensor(value, what);
    core::Dtype dtype = core::Dtype::Float32;
    if (py::isinstance<py::array_t<uint8_t>>(array)) {
        dtype = core::Dtype::UInt8;
    } else if (py::isinstance<py::array_t<uint16_t>>(array)) {
        dtype = core::Dtype::UInt16;
    }
    core::SizeVector shape(array.shape(), array.shape() + array.ndim());
    core::Tensor tensor = core::Tensor::Empty(shape, dtype);
    // A C-contiguous copy of whatever layout came in (slices, transposes).
    const py::array contiguous = py::array::ensure(array, py::array::c_style);
    if (tensor.NumBytes() > 0) std::memcpy(tensor.RawData(), contiguous.data(), tensor.NumBytes());
    if (dtype == core::Dtype::Float32 && !allow_non_finite) {
        const float* data = tensor.Data<float>();
        const int64_t count = tensor.NumElements();
        for (int64_t i = 0; i < count; ++i) {
            if (std::isfinite(data[i])) continue;
            const int64_t row_size = shape.empty() || shape[0] == 0 ? 1 : count / shape[0];
            core::ThrowError(
                "{}: row {} holds {} (the first non-finite value); NaN and infinity break "
                "sorting and blending, as the file readers say too",
                what, i / row_size, data[i]);
        }
    }
    return tensor;
}

}  // namespace pybind
}  // namespace open3d
