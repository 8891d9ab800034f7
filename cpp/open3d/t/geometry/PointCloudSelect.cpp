// PointCloud's selection: rows by index, by mask, inside a box (PointCloud.h). Every attribute
// is copied row by row as raw bytes, so whatever the dtype the selected rows are the source's
// bit for bit.
#include <algorithm>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace t {
namespace geometry {

namespace {

int64_t RowBytes(const core::Tensor& tensor) {
    const int64_t rows = tensor.GetShape().empty() ? 1 : tensor.GetShape(0);
    return rows == 0 ? 0 : tensor.NumBytes() / rows;
}

core::SizeVector WithRows(core::SizeVector shape, int64_t rows) {
    if (shape.empty()) shape.push_back(rows);
    shape[0] = rows;
    return shape;
}

// The rows `indices` (checked by the caller) of every attribute.
PointCloud CopyRows(const PointCloud& cloud, const std::vector<int64_t>& indices) {
    PointCloud out;
    // Positions first: SetPointAttr checks the other attributes' rows against them.
    std::vector<std::string> names = cloud.GetPointAttrNames();
    std::stable_partition(names.begin(), names.end(),
                          [](const std::string& name) { return name == gs_attr::kPositions; });
    for (const std::string& name : names) {
        const core::Tensor& source = cloud.GetPointAttr(name);
        const int64_t row = RowBytes(source);
        core::Tensor selected = core::Tensor::Empty(
            WithRows(source.GetShape(), int64_t(indices.size())), source.GetDtype());
        const auto* from = static_cast<const uint8_t*>(source.RawData());
        auto* to = static_cast<uint8_t*>(selected.RawData());
        for (size_t k = 0; k < indices.size(); ++k) {
            std::memcpy(to + k * row, from + indices[k] * row, size_t(row));
        }
        out.SetPointAttr(name, std::move(selected));
    }
    return out;
}

// The rows whose flag equals `keep`, in cloud order.
std::vector<int64_t> RowsWhere(const std::vector<bool>& flags, bool keep) {
    std::vector<int64_t> rows;
    for (size_t i = 0; i < flags.size(); ++i) {
        if (flags[i] == keep) rows.push_back(int64_t(i));
    }
    return rows;
}

PointCloud CropBy(const PointCloud& cloud,
                  const std::function<bool(const Eigen::Vector3d&)>& inside, bool invert) {
    const int64_t n = cloud.NumPoints();
    std::vector<bool> flags(size_t(n), false);
    if (n > 0) {
        const core::Tensor& positions = cloud.GetPointPositions();
        if (positions.GetDtype() != core::Dtype::Float32) {
            core::ThrowError("Crop: positions are {}, Float32 expected",
                             core::DtypeName(positions.GetDtype()));
        }
        const float* p = positions.Data<float>();
        for (int64_t i = 0; i < n; ++i) {
            flags[size_t(i)] = inside(Eigen::Vector3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]));
        }
    }
    return CopyRows(cloud, RowsWhere(flags, !invert));
}

}  // namespace

std::vector<int64_t> ComplementIndices(const std::vector<int64_t>& indices, int64_t n) {
    std::vector<bool> picked(size_t(n), false);
    for (int64_t i : indices) picked[size_t(i)] = true;
    return RowsWhere(picked, false);
}

PointCloud PointCloud::SelectByIndex(const std::vector<int64_t>& indices, bool invert) const {
    const int64_t n = NumPoints();
    for (int64_t i : indices) {
        if (i < 0 || i >= n) {
            core::ThrowError("SelectByIndex: index {} is out of range for {} points", i, n);
        }
    }
    return CopyRows(*this, invert ? ComplementIndices(indices, n) : indices);
}

PointCloud PointCloud::SelectByMask(const std::vector<bool>& mask, bool invert) const {
    if (int64_t(mask.size()) != NumPoints()) {
        core::ThrowError("SelectByMask: the mask has {} entries for {} points (one a point)",
                         mask.size(), NumPoints());
    }
    return CopyRows(*this, RowsWhere(mask, !invert));
}

PointCloud PointCloud::Crop(const AxisAlignedBoundingBox& box, bool invert) const {
    return CropBy(
        *this, [&box](const Eigen::Vector3d& p) { return box.Contains(p); }, invert);
}

PointCloud PointCloud::Crop(const OrientedBoundingBox& box, bool invert) const {
    return CropBy(
        *this, [&box](const Eigen::Vector3d& p) { return box.Contains(p); }, invert);
}

AxisAlignedBoundingBox PointCloud::GetAxisAlignedBoundingBox() const {
    const int64_t n = NumPoints();
    if (n == 0) return AxisAlignedBoundingBox();
    const float* p = GetPointPositions().Data<float>();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (int64_t i = 0; i < n; ++i) {
        const Eigen::Vector3d q(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
    }
    return AxisAlignedBoundingBox(lo, hi);
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
