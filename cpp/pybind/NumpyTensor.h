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
/// A copy of `array` as a tensor of the array's dtype (float32, uint8 or uint16, any
/// C-contiguous layout after numpy's conversion); throws core::Open3DError naming `what`
/// for other dtypes.
core::Tensor TensorFromArray(const pybind11::array& array, const std::string& what);

}  // namespace pybind
}  // namespace open3d
