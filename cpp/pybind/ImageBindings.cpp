// io.read_image / io.write_image (also under t.io), Open3D's names for image files: PNG
// (8-bit grey, grey + alpha, RGB, RGBA; 16-bit grey) and .npy, as numpy arrays.
#include <pybind11/numpy.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

#include "Bindings.h"
#include "NumpyTensor.h"
#include "PathArgs.h"
#include "open3d/core/Exception.h"
#include "open3d/t/io/ImageIO.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

namespace {

std::string Extension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

}  // namespace

t::geometry::Image ImageFromArray(const py::object& value) {
    py::array array = py::module_::import("numpy").attr("asarray")(value);
    const char kind = array.dtype().kind();
    if ((kind == 'i' || kind == 'u') && !py::isinstance<py::array_t<uint8_t>>(array) &&
        !py::isinstance<py::array_t<uint16_t>>(array)) {
        // float32 would be read as a render in 0..1: say what the pixels should be instead.
        core::ThrowError("write_image: dtype {}: integer images are uint8 (or uint16 grey)",
                         std::string(py::str(array.dtype())));
    }
    array = ArrayForTensor(array, "write_image: image");
    if (array.ndim() == 2) array = array.attr("reshape")(array.shape(0), array.shape(1), 1);
    if (array.ndim() != 3 || array.shape(2) < 1 || array.shape(2) > 4) {
        core::ThrowError("write_image: an image is (H, W) or (H, W, C) with C 1..4, got shape {}",
                         std::string(py::str(array.attr("shape"))));
    }
    // NaN is a value a float image may hold (a depth hole); PNG rounding clamps it.
    return t::geometry::Image(TensorFromArray(array, "write_image: image", true));
}

namespace {

void WritePng(const std::string& path, const t::geometry::Image& image) {
    const int64_t channels = image.GetChannels();
    switch (image.GetDtype()) {
        case core::Dtype::UInt8:
            t::io::WritePNG(path, image);
            return;
        case core::Dtype::UInt16:
            if (channels != 1) {
                core::ThrowError(
                    "write_image: a 16-bit PNG is grey: uint16 (H, W), got {} channels", channels);
            }
            t::io::WritePNG16(path, image.ToFloat(), 1.0);  // exact: every uint16 is a float
            return;
        case core::Dtype::Float32:
            if (channels < 3) {
                core::ThrowError(
                    "write_image: a float (H, W) image (a depth) is not written as 8-bit PNG; "
                    "scale it to uint16 (millimetres: (depth * 1000).astype(numpy.uint16)) or "
                    "write .npy");
            }
            // A render: its colour rounded to 8 bits. The alpha is left out: the colour is
            // premultiplied (or already over the background), and PNG's straight alpha would
            // apply coverage a second time. Pass uint8 RGBA to write an alpha channel.
            t::io::WritePNG(path, image.SelectChannels(0, 3).ToUInt8());
            return;
        case core::Dtype::Int32:
            core::ThrowError(
                "write_image: an int32 image (splat IDs) has no PNG form here; write .npy");
    }
}

py::array ReadImage(const std::filesystem::path& filename) {
    const std::string path = InputPath(filename);
    const std::string ext = Extension(filename);
    t::geometry::Image image;
    if (ext == ".png") {
        py::gil_scoped_release release;
        image = t::io::ReadPNG(path);
    } else if (ext == ".npy") {
        py::gil_scoped_release release;
        image = t::io::ReadNpy(path);
    } else {
        core::ThrowError("read_image: '{}': format '{}' (.png or .npy)", path, ext);
    }
    // ReadPNG gives a 16-bit file's raw values as float; Open3D gives them as uint16.
    const bool png16 = ext == ".png" && image.GetDtype() == core::Dtype::Float32;
    py::array array = ArrayFromImage(std::move(image), true);
    if (png16) array = array.attr("astype")("uint16");
    return array;
}

bool WriteImage(const std::filesystem::path& filename, const py::object& value, int quality) {
    (void)quality;  // Open3D's JPEG quality; PNG is lossless
    const std::string path = PathString(filename);
    const std::string ext = Extension(filename);
    if (ext != ".png" && ext != ".npy") {
        core::ThrowError("write_image: '{}': format '{}' (.png or .npy)", path, ext);
    }
    const t::geometry::Image image = ImageFromArray(value);
    py::gil_scoped_release release;
    if (ext == ".png") {
        WritePng(path, image);
    } else {
        t::io::WriteNpy(path, image);
    }
    return true;
}

}  // namespace

void BindImageIo(py::module_& m) {
    m.def("read_image", &ReadImage, py::arg("filename"),
          "An image file as a numpy array: PNG 8-bit as uint8 (H, W) grey or (H, W, C), 16-bit "
          "grey as uint16 (H, W); .npy as stored (float32, uint8 or uint16). filename is a str "
          "or os.PathLike; a missing file raises Open3DFileNotFoundError.");
    m.def("write_image", &WriteImage, py::arg("filename"), py::arg("image"),
          py::arg("quality") = -1,
          "Writes a numpy image by extension and returns True (Open3D's bool; failures raise "
          "Open3DError). .png: uint8 (H, W) or (H, W, C) as it is, uint16 (H, W) as 16-bit grey, "
          "a float RGB(A) render as its 8-bit colour, round(clamp(v, 0, 1) * 255), without the "
          "alpha (premultiplied colour under PNG's straight alpha would be faded twice). .npy: "
          "exact. quality is Open3D's JPEG setting, unused here.");
}

}  // namespace pybind
}  // namespace open3d
