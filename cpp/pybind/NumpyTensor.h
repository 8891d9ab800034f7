// Between core::Tensor / t::geometry::Image and numpy arrays (docs/python.md "Arrays").
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <string>

#include "open3d/core/Tensor.h"
#include "open3d/t/geometry/Image.h"

namespace open3d {
namespace pybind {

/// A numpy array over `tensor`'s memory (no copy); `owner` keeps that memory alive.
pybind11::array ViewOfTensor(core::Tensor& tensor, pybind11::object owner);
/// The image moved into the array's own keeper: a numpy array of shape (H, W, C), or
/// (H, W) when `squeeze_channel` and C == 1, without a copy.
pybind11::array ArrayFromImage(t::geometry::Image&& image, bool squeeze_channel = false);
/// `value` (an array, a list, anything numpy.asarray takes) as an array of a dtype the
/// library's tensors hold: float32, uint8 and uint16 as they are; float16, float64 (and
/// other floating dtypes) and integers that float32 holds exactly converted to float32.
/// Throws core::Open3DError naming `what` for other dtypes, for float64 values beyond
/// float32's range, and for values numpy cannot make an array of.
pybind11::array ArrayForTensor(const pybind11::handle& value, const std::string& what);
/// A C-order copy of ArrayForTensor(value) as a tensor. Unless `allow_non_finite`, a NaN or
/// infinity is refused with core::Open3DError naming `what` and the first row holding one
/// (the file readers refuse them too: they break sorting and blending).
core::Tensor TensorFromArray(const pybind11::handle& value, const std::string& what,
                             bool allow_non_finite = false);

}  // namespace pybind
}  // namespace open3d
