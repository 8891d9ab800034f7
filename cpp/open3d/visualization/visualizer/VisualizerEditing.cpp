// Editing splat clouds in the viewer (docs/viewer.md "Editing"): picking a pixel through the
// composite's ID image, rectangle selection, inverting, deleting with undo, and saving.
#include <GLFW/glfw3.h>
#include <imgui.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "open3d/camera/CameraPath.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/visualization/rendering/filament/MaterialRecord.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatRenderer.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/ViewSelection.h"
#include "open3d/visualization/visualizer/Visualizer.h"

namespace open3d {
namespace visualization {

namespace {

// The renderer view the picks draw: its own key, so the window's view keeps its state.
constexpr uint64_t kPickView = 0x7069636BULL;  // "pick"

// Deep-enough undo for a session of edits without holding every version of a big scene.
constexpr size_t kMaxUndo = 16;

}  // namespace

std::optional<SplatPick> Visualizer::PickSplat(int x, int y) {
    const camera::PinholeCamera camera = view_control_.GetCamera();
    if (x < 0 || y < 0 || x >= camera.width || y >= camera.height) {
        core::ThrowError("PickSplat: pixel ({}, {}) is outside the {}x{} view", x, y, camera.width,
                         camera.height);
    }
    rendering::GaussianSplatRenderer& splats = scene_->GetScene().GetSplatRenderer();
    if (!splats.HasVisibleSplats()) return std::nullopt;
    rendering::RenderOutput out;
    rendering::CompositeInputs inputs;
    inputs.median_depth = false;
    inputs.splat_id = true;
    splats.Prepare();
    splats.RenderGeometryStage(kPickView, camera, scene_->GetSplatConfig());
    splats.RenderCompositeStage(kPickView, out, inputs);
    splats.ReleaseView(kPickView);
    const int64_t pixel = int64_t(y) * camera.width + x;
    const auto where = splats.LocateSplat(out.splat_id.Data<int32_t>()[pixel]);
    if (!where) return std::nullopt;
    SplatPick pick;
    pick.geometry = where->first;
    pick.index = where->second;
    // The ray through the pixel centre, at view z = the expected depth there.
    pick.point = camera.PixelToWorld(x, y, out.depth_expected.Data<float>()[pixel]);
    namespace gs = t::geometry::gs_attr;
    const t::geometry::PointCloud& cloud = splats.GetCloud(pick.geometry);
    const int64_t i = pick.index;
    const auto row = [&](const char* name, int64_t width) {
        return cloud.GetPointAttr(name).Data<float>() + i * width;
    };
    const float* c = row(gs::kPositions, 3);
    const float* s = row(gs::kScale, 3);
    const float* q = row(gs::kRot, 4);
    const float* dc = row(gs::kFDc, 3);
    pick.center = Eigen::Vector3d(c[0], c[1], c[2]);
    pick.opacity = 1.0 / (1.0 + std::exp(-double(*row(gs::kOpacity, 1))));
    pick.scale = Eigen::Vector3d(s[0], s[1], s[2]);
    pick.rotation = Eigen::Vector4d(q[0], q[1], q[2], q[3]);
    for (int k = 0; k < 3; ++k) pick.color[k] = 0.5 + t::geometry::kSH_C0 * dc[k];
    if (!picks_.empty()) pick.distance_to_previous = (pick.point - picks_.back().point).norm();
    picks_.push_back(pick);
    PostRedraw();
    return pick;
}

int64_t Visualizer::SelectSplats(double x0, double y0, double x1, double y1, bool add) {
    return SelectSplatsInPolygon(rendering::cpu::RectanglePolygon(x0, y0, x1, y1), add);
}

int64_t Visualizer::SelectSplatsInPolygon(const std::vector<Eigen::Vector2d>& polygon, bool add) {
    if (!add) selection_.clear();
    const camera::PinholeCamera camera = view_control_.GetCamera();
    rendering::GaussianSplatRenderer& splats = scene_->GetScene().GetSplatRenderer();
    for (const std::string& name : names_) {
        if (!splats.HasCloud(name) || !splats.IsCloudVisible(name)) continue;
        std::vector<int64_t> chosen = rendering::cpu::SelectSplatsInView(
            splats.GetCloud(name), camera, scene_->GetSplatConfig(), polygon);
        if (chosen.empty()) continue;
        std::vector<int64_t>& kept = selection_[name];
        std::vector<int64_t> merged;
        std::set_union(kept.begin(), kept.end(), chosen.begin(), chosen.end(),
                       std::back_inserter(merged));
        kept = std::move(merged);
    }
    UpdateSelectionOverlay();
    return SelectedCount();
}

int64_t Visualizer::InvertSelection() {
    rendering::GaussianSplatRenderer& splats = scene_->GetScene().GetSplatRenderer();
    for (auto& [name, indices] : selection_) {
        indices = t::geometry::ComplementIndices(indices, splats.GetCloud(name).NumPoints());
    }
    UpdateSelectionOverlay();
    return SelectedCount();
}

int64_t Visualizer::SelectedCount() const {
    int64_t total = 0;
    for (const auto& [name, indices] : selection_) total += static_cast<int64_t>(indices.size());
    return total;
}

void Visualizer::ClearSelection() {
    selection_.clear();
    UpdateSelectionOverlay();
}

void Visualizer::UpdateSelectionOverlay() {
    scene_->RemoveGeometry(kSelectionOverlay);
    PostRedraw();
    rendering::GaussianSplatRenderer& splats = scene_->GetScene().GetSplatRenderer();
    std::vector<float> centres;
    for (const auto& [name, indices] : selection_) {
        if (!splats.HasCloud(name)) continue;
        const float* p = splats.GetCloud(name).GetPointPositions().Data<float>();
        for (int64_t i : indices) centres.insert(centres.end(), p + 3 * i, p + 3 * i + 3);
    }
    ShowOverlayPoints(kSelectionOverlay, centres, Eigen::Vector4f(1.0f, 0.0f, 0.0f, 1.0f), 3.0f);
}

void Visualizer::ShowOverlayPoints(const char* name, const std::vector<float>& points,
                                   const Eigen::Vector4f& color, float point_size) {
    if (points.empty()) return;
    rendering::MaterialRecord material;
    material.shader = rendering::kShaderDefaultUnlit;
    material.base_color = color;
    material.point_size = point_size;
    const int64_t n = static_cast<int64_t>(points.size() / 3);
    scene_->AddGeometry(name, t::geometry::PointCloud(core::Tensor::FromVector(points, {n, 3})),
                        material);
}

void Visualizer::RequireObjectName(const std::string& name) {
    if (name == kSelectionOverlay || name == kCropBoxOverlay) {
        core::ThrowError("'{}' is a name the viewer's editing overlays take; choose another", name);
    }
}

int64_t Visualizer::DeleteSelection() {
    rendering::GaussianSplatRenderer& splats = scene_->GetScene().GetSplatRenderer();
    int64_t removed = 0;
    std::vector<std::pair<std::string, t::geometry::PointCloud>> before;
    for (const auto& [name, indices] : selection_) {
        if (indices.empty() || !splats.HasCloud(name)) continue;
        before.emplace_back(name, splats.GetCloud(name));
        UpdateGeometry(name, before.back().second.RemoveByIndex(indices));
        removed += static_cast<int64_t>(indices.size());
    }
    CommitEdit(std::move(before));
    return removed;
}

int64_t Visualizer::CropSplats(const t::geometry::OrientedBoundingBox& box, bool invert) {
    rendering::GaussianSplatRenderer& splats = scene_->GetScene().GetSplatRenderer();
    int64_t removed = 0;
    std::vector<std::pair<std::string, t::geometry::PointCloud>> before;
    for (const std::string& name : names_) {
        if (!splats.HasCloud(name) || !splats.IsCloudVisible(name)) continue;
        const t::geometry::PointCloud& cloud = splats.GetCloud(name);
        t::geometry::PointCloud cropped = cloud.Crop(box, invert);
        if (cropped.NumPoints() == cloud.NumPoints()) continue;  // nothing left out
        removed += cloud.NumPoints() - cropped.NumPoints();
        before.emplace_back(name, cloud);
        UpdateGeometry(name, cropped);
    }
    CommitEdit(std::move(before));
    return removed;
}

t::geometry::OrientedBoundingBox Visualizer::GetSelectionBox() const {
    const rendering::GaussianSplatRenderer& splats = scene_->GetScene().GetSplatRenderer();
    std::optional<t::geometry::AxisAlignedBoundingBox> box;  // the union of each cloud's box
    for (const auto& [name, indices] : selection_) {
        if (indices.empty()) continue;
        const t::geometry::AxisAlignedBoundingBox part =
            splats.GetCloud(name).SelectByIndex(indices).GetAxisAlignedBoundingBox();
        box = box ? t::geometry::AxisAlignedBoundingBox(
                        box->GetMinBound().cwiseMin(part.GetMinBound()),
                        box->GetMaxBound().cwiseMax(part.GetMaxBound()))
                  : part;
    }
    if (!box) core::ThrowError("GetSelectionBox: nothing is selected");
    return t::geometry::OrientedBoundingBox::FromAxisAligned(*box);
}

void Visualizer::CommitEdit(std::vector<std::pair<std::string, t::geometry::PointCloud>> before) {
    if (!before.empty()) {
        undo_.push_back(std::move(before));
        if (undo_.size() > kMaxUndo) undo_.erase(undo_.begin());
    }
    EndSelectionAndPicks();
}

void Visualizer::EndSelectionAndPicks() {
    selection_.clear();
    picks_.clear();
    UpdateSelectionOverlay();
    if (crop_box_) SetCropBox(crop_box_);  // counts the splats inside the changed clouds again
}

bool Visualizer::UndoEdit() {
    if (undo_.empty()) return false;
    const auto clouds = std::move(undo_.back());
    undo_.pop_back();
    for (const auto& [name, cloud] : clouds) {
        if (scene_->GetScene().GetSplatRenderer().HasCloud(name)) UpdateGeometry(name, cloud);
    }
    EndSelectionAndPicks();
    return true;
}

void Visualizer::SaveGeometry(const std::string& name, const std::string& path) {
    rendering::GaussianSplatRenderer& splats = scene_->GetScene().GetSplatRenderer();
    if (!splats.HasCloud(name)) core::ThrowError("SaveGeometry: no splat cloud named '{}'", name);
    t::io::WritePointCloud(path, splats.GetCloud(name));
}

size_t Visualizer::AddKeyframe() {
    camera::CameraView view;
    view.id = static_cast<int>(keyframes_.size());
    view.img_name = fmt::format("keyframe_{:03d}", keyframes_.size());
    view.camera = view_control_.GetCamera();
    view.time =
        keyframes_.empty() ? 0.0 : *keyframes_.back().time + camera::kDefaultSecondsPerKeyframe;
    keyframes_.push_back(view);
    PostRedraw();
    return keyframes_.size();
}

void Visualizer::SaveKeyframes(const std::string& path) const {
    if (keyframes_.empty()) core::ThrowError("SaveKeyframes: no keyframes (K adds the camera)");
    camera::WriteCamerasJson(path, keyframes_);
}

bool Visualizer::OnEditKey(int key, int mods) {
    const bool ctrl = (mods & GLFW_MOD_CONTROL) != 0;
    try {
        if (key == GLFW_KEY_DELETE && !selection_.empty()) {
            DeleteSelection();
        } else if (ctrl && key == GLFW_KEY_I) {
            InvertSelection();
        } else if (ctrl && key == GLFW_KEY_Z) {
            UndoEdit();
        } else if (mods == 0 && key == GLFW_KEY_K) {
            AddKeyframe();
        } else {
            return false;
        }
        edit_status_.clear();
    } catch (const std::exception& e) {
        edit_status_ = e.what();
    }
    return true;
}

void Visualizer::EndSelectDrag(Drag drag) {
    // Pixels in the window's framebuffer: the cursor is in the same units here (no scaling
    // of a high-density display under X11).
    const double moved = std::hypot(cursor_x_ - press_x_, cursor_y_ - press_y_);
    try {
        if (moved < 3.0) {
            const int x = static_cast<int>(std::lround(press_x_));
            const int y = static_cast<int>(std::lround(press_y_));
            if (x >= 0 && y >= 0 && x < fb_width_ && y < fb_height_) PickSplat(x, y);
        } else if (lasso_ && lasso_points_.size() >= 3) {
            SelectSplatsInPolygon(lasso_points_, drag == Drag::kSelectAdd);
        } else {
            SelectSplats(press_x_, press_y_, cursor_x_, cursor_y_, drag == Drag::kSelectAdd);
        }
        edit_status_.clear();
    } catch (const std::exception& e) {
        edit_status_ = e.what();
    }
    PostRedraw();
}

void Visualizer::DrawEditingPanel() {
    const int64_t selected = SelectedCount();
    if (!picks_.empty()) {
        const SplatPick& p = picks_.back();
        ImGui::Text("Picked %s #%lld", p.geometry.c_str(), static_cast<long long>(p.index));
        ImGui::Text("  at (%.4g, %.4g, %.4g)", p.point.x(), p.point.y(), p.point.z());
        if (p.distance_to_previous >= 0.0) {
            ImGui::Text("  %.4g from the previous pick", p.distance_to_previous);
        }
        ImGui::Text("  opacity %.3f, colour (%.3f, %.3f, %.3f)", p.opacity, p.color.x(),
                    p.color.y(), p.color.z());
        ImGui::Text("  scale (%.3g, %.3g, %.3g)", p.scale.x(), p.scale.y(), p.scale.z());
    }
    ImGui::Text("Selected %lld splats", static_cast<long long>(selected));
    // The buttons run what the keys run, errors included.
    if (selected > 0) {
        if (ImGui::Button("Delete (Del)")) OnEditKey(GLFW_KEY_DELETE, 0);
        ImGui::SameLine();
        if (ImGui::Button("Invert (Ctrl+I)")) OnEditKey(GLFW_KEY_I, GLFW_MOD_CONTROL);
        ImGui::SameLine();
        if (ImGui::Button("Clear")) ClearSelection();
        if (ImGui::Button("Crop to the selection's box")) {
            try {
                CropSplats(GetSelectionBox());
                edit_status_.clear();
            } catch (const std::exception& e) {
                edit_status_ = e.what();
            }
        }
    }
    DrawCropBoxPanel();
    if (!undo_.empty() && ImGui::Button("Undo (Ctrl+Z)")) OnEditKey(GLFW_KEY_Z, GLFW_MOD_CONTROL);
    ImGui::Text("Camera path: %zu keyframes", keyframes_.size());
    if (ImGui::Button("Add keyframe (K)")) OnEditKey(GLFW_KEY_K, 0);
    if (!keyframes_.empty()) {
        ImGui::SameLine();
        if (ImGui::Button("Clear keyframes")) ClearKeyframes();
    }
    // One file field for what the buttons below write (the extension picks a cloud's format).
    ImGui::SetNextItemWidth(ImGui::GetFontSize() * 16.0f);
    ImGui::InputTextWithHint("##edit_path", "file to save to", edit_path_, sizeof(edit_path_));
    const auto save = [&](const std::function<void(const std::string&)>& write) {
        try {
            if (edit_path_[0] == '\0') core::ThrowError("type a file name to save to first");
            write(edit_path_);
            edit_status_ = fmt::format("Saved {}", edit_path_);
        } catch (const std::exception& e) {
            edit_status_ = e.what();
        }
    };
    if (!keyframes_.empty() && ImGui::Button("Save camera path")) {
        save([&](const std::string& path) { SaveKeyframes(path); });
    }
    rendering::GaussianSplatRenderer& splats = scene_->GetScene().GetSplatRenderer();
    for (const std::string& name : names_) {
        if (!splats.HasCloud(name)) continue;
        if (ImGui::Button(fmt::format("Save {}", name).c_str())) {
            save([&](const std::string& path) { SaveGeometry(name, path); });
        }
    }
    if (!edit_status_.empty()) ImGui::TextWrapped("%s", edit_status_.c_str());
}

}  // namespace visualization
}  // namespace open3d
