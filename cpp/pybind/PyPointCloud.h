// Python's PointCloud: the C++ cloud plus a count of the live numpy views of each attribute,
// so that an attribute is never replaced or removed while a view still points into it.
#pragma once

#include <map>
#include <string>

#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace pybind {

struct PyPointCloud {
    t::geometry::PointCloud cloud;
    std::map<std::string, int> views;
    /// Throws core::Open3DError when `name` has live views (`action`: "replace", "remove").
    void RequireNoViews(const std::string& name, const char* action) const;
};

}  // namespace pybind
}  // namespace open3d
