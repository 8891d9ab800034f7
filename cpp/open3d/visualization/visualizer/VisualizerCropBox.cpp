// The viewer's crop box (docs/viewer.md "Editing"): an axis-aligned box started from the
// selection or the scene's bounds, its corners dragged in the panel, drawn in the window as its
// edges, and applied as one undoable crop that keeps (or removes) the splats inside.
#include <imgui.h>

#include <algorithm>
#include <exception>
#include <optional>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatRenderer.h"
#include "open3d/visualization/visualizer/Visualizer.h"

namespace open3d {
namespace visualization {

namespace {

// Points per edge of the drawn box: dense enough to read as lines at any window size.
constexpr int kPointsPerEdge = 96;

// Splats of `cloud` whose centre lies in `box` (its faces included, as PointCloud::Crop does).
int64_t CountInside(const t::geometry::PointCloud& cloud,
                    const t::geometry::AxisAlignedBoundingBox& box) {
    const float* p = cloud.GetPointPositions().Data<float>();
    const Eigen::Vector3d lo = box.GetMinBound(), hi = box.GetMaxBound();
    int64_t inside = 0;
    for (int64_t i = 0; i < cloud.NumPoints(); ++i) {
        bool in = true;
        for (int k = 0; k < 3; ++k) in = in && p[3 * i + k] >= lo[k] && p[3 * i + k] <= hi[k];
        inside += in;
    }
    return inside;
}

}  // namespace

t::geometry::AxisAlignedBoundingBox Visualizer::DefaultCropBox() const {
    if (SelectedCount() > 0) {
        const t::geometry::OrientedBoundingBox box = GetSelectionBox();
        return t::geometry::AxisAlignedBoundingBox(box.GetCenter() - 0.5 * box.GetExtent(),
                                                   box.GetCenter() + 0.5 * box.GetExtent());
    }
    const rendering::GaussianSplatRenderer& splats = scene_->GetScene().GetSplatRenderer();
    std::optional<t::geometry::AxisAlignedBoundingBox> box;
    for (const std::string& name : names_) {
        if (!splats.HasCloud(name) || !splats.IsCloudVisible(name)) continue;
        const t::geometry::PointCloud& cloud = splats.GetCloud(name);
        if (cloud.NumPoints() == 0) continue;
        const t::geometry::AxisAlignedBoundingBox part = cloud.GetAxisAlignedBoundingBox();
        box = box ? t::geometry::AxisAlignedBoundingBox(
                        box->GetMinBound().cwiseMin(part.GetMinBound()),
                        box->GetMaxBound().cwiseMax(part.GetMaxBound()))
                  : part;
    }
    if (!box) core::ThrowError("DefaultCropBox: no splat cloud is shown");
    return *box;
}

void Visualizer::SetCropBox(const std::optional<t::geometry::AxisAlignedBoundingBox>& box) {
    crop_box_ = box;
    crop_box_inside_ = 0;
    if (box) {
        const rendering::GaussianSplatRenderer& splats = scene_->GetScene().GetSplatRenderer();
        for (const std::string& name : names_) {
            if (splats.HasCloud(name) && splats.IsCloudVisible(name))
                crop_box_inside_ += CountInside(splats.GetCloud(name), *box);
        }
    }
    UpdateCropBoxOverlay();
}

int64_t Visualizer::ApplyCropBox(bool invert) {
    if (!crop_box_) core::ThrowError("ApplyCropBox: there is no crop box (SetCropBox)");
    const int64_t removed =
        CropSplats(t::geometry::OrientedBoundingBox::FromAxisAligned(*crop_box_), invert);
    SetCropBox(std::nullopt);
    return removed;
}

void Visualizer::UpdateCropBoxOverlay() {
    scene_->RemoveGeometry(kCropBoxOverlay);
    PostRedraw();
    if (!crop_box_) return;
    const Eigen::Vector3d lo = crop_box_->GetMinBound(), hi = crop_box_->GetMaxBound();
    std::vector<float> points;
    // The 12 edges: for each axis, the 4 edges along it at the other two axes' min and max.
    for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        for (int corner = 0; corner < 4; ++corner) {
            Eigen::Vector3d p;
            p[u] = (corner & 1) ? hi[u] : lo[u];
            p[v] = (corner & 2) ? hi[v] : lo[v];
            for (int k = 0; k <= kPointsPerEdge; ++k) {
                p[axis] = lo[axis] + (hi[axis] - lo[axis]) * k / kPointsPerEdge;
                for (int c = 0; c < 3; ++c) points.push_back(static_cast<float>(p[c]));
            }
        }
    }
    ShowOverlayPoints(kCropBoxOverlay, points, Eigen::Vector4f(1.0f, 0.85f, 0.0f, 1.0f), 2.0f);
}

void Visualizer::DrawCropBoxPanel() {
    try {
        if (!crop_box_) {
            if (ImGui::Button("Crop box")) SetCropBox(DefaultCropBox());
            return;
        }
        Eigen::Vector3f lo = crop_box_->GetMinBound().cast<float>();
        Eigen::Vector3f hi = crop_box_->GetMaxBound().cast<float>();
        // A mouse drag across the field moves a corner by 1/200 of the box's largest side per
        // pixel; a double click types a value.
        const float speed = std::max(1e-6f, (hi - lo).maxCoeff() / 200.0f);
        bool changed = ImGui::DragFloat3("min corner", lo.data(), speed, 0.0f, 0.0f, "%.4g");
        changed = ImGui::DragFloat3("max corner", hi.data(), speed, 0.0f, 0.0f, "%.4g") || changed;
        if (changed) {
            // A corner dragged past the other stops there: the box never turns inside out.
            const Eigen::Vector3f new_lo = lo.cwiseMin(hi), new_hi = hi.cwiseMax(new_lo);
            SetCropBox(
                t::geometry::AxisAlignedBoundingBox(new_lo.cast<double>(), new_hi.cast<double>()));
        }
        ImGui::Text("%lld splats inside", static_cast<long long>(crop_box_inside_));
        if (ImGui::Button("Keep inside")) ApplyCropBox(false);
        ImGui::SameLine();
        if (crop_box_ && ImGui::Button("Remove inside")) ApplyCropBox(true);
        ImGui::SameLine();
        if (crop_box_ && ImGui::Button("Cancel box")) SetCropBox(std::nullopt);
        edit_status_.clear();
    } catch (const std::exception& e) {
        edit_status_ = e.what();
    }
}

}  // namespace visualization
}  // namespace open3d
