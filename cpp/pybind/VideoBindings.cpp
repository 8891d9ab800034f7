// io.VideoWriter: frames (numpy images, e.g. a render_batch's) into an H.264 MP4
// (t/io/H264VideoWriter.h; docs/camera-paths.md "Python").
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <memory>
#include <string>

#include "Bindings.h"
#include "PathArgs.h"
#include "open3d/core/Exception.h"
#include "open3d/t/io/H264VideoWriter.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

namespace {

class PyVideoWriter {
public:
    PyVideoWriter(const std::filesystem::path& filename, int width, int height, double fps,
                  float crf, const std::string& preset)
        : path_(PathString(filename)), width_(width), height_(height) {
        t::io::H264VideoOptions options;
        options.crf = crf;
        options.preset = preset;
        writer_ = std::make_unique<t::io::H264VideoWriter>(path_, width, height, fps, options);
    }

    void Write(const py::object& value) {
        if (!writer_) core::ThrowError("VideoWriter '{}': already closed", path_);
        t::geometry::Image image = ImageFromArray(value);
        if (image.GetRows() != height_ || image.GetCols() != width_ || image.GetChannels() < 3) {
            core::ThrowError(
                "VideoWriter '{}': frame {} is {}x{} with {} channels; the video takes {}x{} "
                "(W x H) RGB or RGBA",
                path_, frames_, image.GetCols(), image.GetRows(), image.GetChannels(), width_,
                height_);
        }
        if (image.GetDtype() == core::Dtype::Float32) {
            image = image.SelectChannels(0, 3).ToUInt8();  // a render: round(clamp(v) * 255)
        } else if (image.GetDtype() != core::Dtype::UInt8) {
            core::ThrowError("VideoWriter '{}': frames are uint8 or float32 renders", path_);
        }
        py::gil_scoped_release release;
        writer_->WriteFrame(image.Data<uint8_t>(), int(image.GetChannels()));
        ++frames_;
    }

    size_t Close() {
        if (!writer_) return frames_;
        py::gil_scoped_release release;
        writer_->Finish();
        writer_.reset();
        return frames_;
    }

    // Leaves no file: the temporary goes with the writer.
    void Abandon() { writer_.reset(); }

private:
    std::string path_;
    int width_, height_;
    size_t frames_ = 0;
    std::unique_ptr<t::io::H264VideoWriter> writer_;
};

}  // namespace

void BindVideo(py::module_& m) {
    py::class_<PyVideoWriter>(
        m, "VideoWriter",
        "An H.264 MP4 written frame by frame (libx264, BT.709 4:2:0; an odd width or height "
        "gets one edge column or row of padding). The file appears when close() succeeds "
        "(or the with-block ends without an exception); until then it is a temporary, "
        "removed if the writer is dropped or the block raises.")
        .def(py::init<const std::filesystem::path&, int, int, double, float, const std::string&>(),
             py::arg("filename"), py::arg("width"), py::arg("height"), py::arg("fps") = 30.0,
             py::arg("crf") = 23.0f, py::arg("preset") = "veryfast",
             "crf: x264's constant rate factor, 1 (best) to 51; preset: x264's speed "
             "preset (ultrafast .. veryslow).")
        .def("write", &PyVideoWriter::Write, py::arg("image"),
             "Appends a frame: uint8 (H, W, 3|4) as it is, or a float32 render (H, W, 3|4) "
             "as round(clamp(v, 0, 1) * 255); the alpha is ignored.")
        .def("close", &PyVideoWriter::Close,
             "Encodes the frames still held, writes the index, publishes the file; returns "
             "the frame count.")
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__",
             [](PyVideoWriter& w, const py::object& type, const py::object&, const py::object&) {
                 if (type.is_none()) {
                     w.Close();
                 } else {
                     w.Abandon();
                 }
                 return false;
             });
}

}  // namespace pybind
}  // namespace open3d
