// Editing in the viewer (docs/viewer.md "Editing"): a Ctrl + click picks the splat the CPU
// reference picks at that pixel, a Ctrl + drag selects what cpu::SelectSplatsInView selects,
// Delete (sent through the X server, as another client would) removes exactly those splats,
// Ctrl + I inverts, Ctrl + Z restores the cloud bit for bit (every cloud one removal changed),
// the edit saves to a file, a Ctrl + Alt drag selects a lasso's polygon, cropping to the
// selection's box keeps what PointCloud::Crop keeps, so does the crop box (drawn as yellow
// edges while it is edited), K records keyframes that save as a camera path, and the selection
// shows as red points.
#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "TestUtility.h"
#include "XKeySender.h"
#include "open3d/camera/CameraPath.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Picking.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/ViewSelection.h"
#include "visualization/visualizer/VisualizerTestFixture.h"

namespace open3d {
namespace tests {
namespace {

class VisualizerEditing : public VisualizerTest {
protected:
    // A 160 x 120 window showing the default scene as "scene", the camera fitted, one frame
    // drawn.
    visualization::Visualizer& ShowScene() {
        visualization::Visualizer& vis = MakeVisualizer(160, 120);
        vis.AddGeometry("scene", cloud_);
        vis.ResetCamera();
        EXPECT_TRUE(vis.RenderFrame());
        return vis;
    }
    const t::geometry::PointCloud cloud_ = rendering::CreateDefaultGaussianSplatScene();
};

bool SameCloud(const t::geometry::PointCloud& a, const t::geometry::PointCloud& b) {
    if (a.NumPoints() != b.NumPoints()) return false;
    if (a.GetPointAttrNames() != b.GetPointAttrNames()) return false;
    for (const std::string& name : a.GetPointAttrNames()) {
        if (!(b.GetPointAttr(name) == a.GetPointAttr(name))) return false;
    }
    return true;
}

void Click(visualization::Visualizer& vis, double x, double y, int mods) {
    vis.OnCursorPos(x, y);
    vis.OnMouseButton(GLFW_MOUSE_BUTTON_LEFT, true, mods);
    vis.OnMouseButton(GLFW_MOUSE_BUTTON_LEFT, false, mods);
}

TEST_F(VisualizerEditing, PickSelectDeleteInvertUndoAndSave) {
    visualization::Visualizer& vis = ShowScene();
    const t::geometry::PointCloud& cloud = cloud_;
    const camera::PinholeCamera cam = vis.GetCamera();
    const rendering::RenderConfig& config = vis.GetSplatConfig();

    // A click: the reference's pick of that pixel, and its point.
    const int px = cam.width / 2, py = cam.height / 2;
    Click(vis, px, py, GLFW_MOD_CONTROL);
    ASSERT_EQ(vis.GetPicks().size(), 1u);
    const rendering::cpu::PickResult ref = rendering::cpu::PickPixel(cloud, cam, config, px, py);
    ASSERT_TRUE(ref.hit);
    EXPECT_EQ(vis.GetPicks()[0].geometry, "scene");
    EXPECT_EQ(vis.GetPicks()[0].index, ref.splat);
    // The viewer's point comes from the backend's float32 depth image: 1e-5 relative
    // covers its rounding (the reference's depth is double).
    EXPECT_LE((vis.GetPicks()[0].point - ref.point).norm(), 1e-5 * ref.point.norm() + 1e-6);
    EXPECT_LT(vis.GetPicks()[0].distance_to_previous, 0.0);
    // The panel's attributes, from the cloud's row: centre, sigmoid of the stored opacity,
    // scale, rotation and 0.5 + C0 f_dc.
    {
        namespace gs = t::geometry::gs_attr;
        const visualization::SplatPick& p = vis.GetPicks()[0];
        const auto at = [&](const char* name, int64_t width, int k) {
            return double(cloud.GetPointAttr(name).Data<float>()[p.index * width + k]);
        };
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(p.center[k], at(gs::kPositions, 3, k));
            EXPECT_EQ(p.scale[k], at(gs::kScale, 3, k));
            EXPECT_DOUBLE_EQ(p.color[k], 0.5 + 0.28209479177387814 * at(gs::kFDc, 3, k));
        }
        EXPECT_EQ(p.rotation[0], at(gs::kRot, 4, 0));
        EXPECT_DOUBLE_EQ(p.opacity, 1.0 / (1.0 + std::exp(-at(gs::kOpacity, 1, 0))));
        EXPECT_GT(p.opacity, 0.0);
    }
    Click(vis, px + 10, py + 5, GLFW_MOD_CONTROL);
    ASSERT_EQ(vis.GetPicks().size(), 2u);
    EXPECT_NEAR(vis.GetPicks()[1].distance_to_previous,
                (vis.GetPicks()[1].point - vis.GetPicks()[0].point).norm(), 1e-12);

    // A Ctrl + drag over a rectangle selects what the reference selects there.
    vis.OnCursorPos(40, 30);
    vis.OnMouseButton(GLFW_MOUSE_BUTTON_LEFT, true, GLFW_MOD_CONTROL);
    vis.OnCursorPos(100, 80);
    vis.OnMouseButton(GLFW_MOUSE_BUTTON_LEFT, false, GLFW_MOD_CONTROL);
    const std::vector<int64_t> want = rendering::cpu::SelectSplatsInView(
        cloud, cam, config, rendering::cpu::RectanglePolygon(40, 30, 100, 80));
    ASSERT_GT(want.size(), 10u);
    ASSERT_EQ(vis.GetSelection().count("scene"), 1u);
    EXPECT_EQ(vis.GetSelection().at("scene"), want);

    // Ctrl + I twice: the complement, then the selection again.
    vis.OnKey(GLFW_KEY_I, true, false, GLFW_MOD_CONTROL);
    EXPECT_EQ(vis.GetSelection().at("scene").size(), size_t(cloud.NumPoints()) - want.size());
    vis.OnKey(GLFW_KEY_I, true, false, GLFW_MOD_CONTROL);
    EXPECT_EQ(vis.GetSelection().at("scene"), want);

    // Delete through the X server: the viewer sees it when it polls.
    ASSERT_TRUE(SendXKey(vis.GetX11WindowId(), "Delete"));
    const rendering::GaussianSplatRenderer& splats = vis.GetScene().GetScene().GetSplatRenderer();
    for (int i = 0; i < 600 && splats.GetCloud("scene").NumPoints() == cloud.NumPoints(); ++i) {
        vis.PollEvents();  // a real hang only reaches the bound (a minute of polls)
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    const t::geometry::PointCloud edited = splats.GetCloud("scene");
    EXPECT_TRUE(SameCloud(edited, cloud.RemoveByIndex(want)));
    EXPECT_TRUE(vis.GetSelection().empty());
    ASSERT_TRUE(vis.RenderFrame());  // the edited scene draws

    // Saved in a writable format: what the whole scene's round trip gives for those splats
    // (a scale without an exact float32 log comes back an ulp off, in both alike;
    // docs/editing.md "Writing an edited scene").
    const std::filesystem::path dir(TempDir());
    const std::string path = (dir / "visualizer_editing_edited.ply").string();
    const std::string whole = (dir / "visualizer_editing_whole.ply").string();
    vis.SaveGeometry("scene", path);
    t::io::WritePointCloud(whole, cloud);
    t::geometry::PointCloud saved, whole_read;
    t::io::ReadPointCloud(path, saved);
    t::io::ReadPointCloud(whole, whole_read);
    std::filesystem::remove(path);
    std::filesystem::remove(whole);
    EXPECT_TRUE(SameCloud(saved, whole_read.RemoveByIndex(want)));

    // Ctrl + Z: the cloud as it was, bit for bit; nothing more to undo.
    vis.OnKey(GLFW_KEY_Z, true, false, GLFW_MOD_CONTROL);
    EXPECT_TRUE(SameCloud(splats.GetCloud("scene"), cloud));
    EXPECT_FALSE(vis.UndoEdit());
    ASSERT_TRUE(vis.RenderFrame());
}

TEST_F(VisualizerEditing, OneUndoRestoresEveryCloudADeleteChanged) {
    visualization::Visualizer& vis = MakeVisualizer(160, 120);
    const t::geometry::PointCloud cloud = rendering::CreateDefaultGaussianSplatScene();
    std::vector<int64_t> first_half;
    for (int64_t i = 0; i < cloud.NumPoints() / 2; ++i) first_half.push_back(i);
    const t::geometry::PointCloud a = cloud.SelectByIndex(first_half);
    const t::geometry::PointCloud b = cloud.RemoveByIndex(first_half);
    vis.AddGeometry("a", a);
    vis.AddGeometry("b", b);
    vis.ResetCamera();
    ASSERT_TRUE(vis.RenderFrame());
    // The whole window: both clouds have selected splats.
    vis.SelectSplats(0, 0, vis.GetWidth() - 1, vis.GetHeight() - 1);
    ASSERT_EQ(vis.GetSelection().size(), 2u);
    EXPECT_GT(vis.DeleteSelection(), 0);
    const rendering::GaussianSplatRenderer& splats = vis.GetScene().GetScene().GetSplatRenderer();
    EXPECT_LT(splats.GetCloud("a").NumPoints(), a.NumPoints());
    EXPECT_LT(splats.GetCloud("b").NumPoints(), b.NumPoints());
    ASSERT_TRUE(vis.UndoEdit());
    EXPECT_TRUE(SameCloud(splats.GetCloud("a"), a));
    EXPECT_TRUE(SameCloud(splats.GetCloud("b"), b));
    EXPECT_FALSE(vis.UndoEdit());
}

TEST_F(VisualizerEditing, ALassoSelectsWhatTheReferenceSelectsInItsPolygon) {
    visualization::Visualizer& vis = ShowScene();
    const t::geometry::PointCloud& cloud = cloud_;
    // Ctrl + Alt + drag through a triangle: the press and every cursor position are its
    // vertices.
    const int mods = GLFW_MOD_CONTROL | GLFW_MOD_ALT;
    vis.OnCursorPos(40, 30);
    vis.OnMouseButton(GLFW_MOUSE_BUTTON_LEFT, true, mods);
    vis.OnCursorPos(110, 40);
    vis.OnCursorPos(70, 90);
    vis.OnMouseButton(GLFW_MOUSE_BUTTON_LEFT, false, mods);
    const std::vector<int64_t> want = rendering::cpu::SelectSplatsInView(
        cloud, vis.GetCamera(), vis.GetSplatConfig(), {{40, 30}, {110, 40}, {70, 90}});
    ASSERT_GT(want.size(), 10u);
    ASSERT_EQ(vis.GetSelection().count("scene"), 1u);
    EXPECT_EQ(vis.GetSelection().at("scene"), want);
    // The triangle holds fewer than its bounding rectangle.
    EXPECT_LT(want.size(),
              rendering::cpu::SelectSplatsInView(cloud, vis.GetCamera(), vis.GetSplatConfig(),
                                                 rendering::cpu::RectanglePolygon(40, 30, 110, 90))
                  .size());
}

TEST_F(VisualizerEditing, KeyframesRecordTheCameraAndSaveAsACameraPath) {
    visualization::Visualizer& vis = ShowScene();
    PressKey(vis, GLFW_KEY_K);
    const camera::PinholeCamera first = vis.GetCamera();
    vis.GetViewControl().Rotate(40, 10);
    PressKey(vis, GLFW_KEY_K);
    const camera::PinholeCamera second = vis.GetCamera();
    ASSERT_EQ(vis.GetKeyframes().size(), 2u);
    EXPECT_EQ(*vis.GetKeyframes()[0].time, 0.0);
    EXPECT_EQ(*vis.GetKeyframes()[1].time, 2.0);
    const std::string path = (std::filesystem::path(TempDir()) / "viewer_keyframes.json").string();
    vis.SaveKeyframes(path);
    const std::vector<camera::CameraView> read = camera::ReadCamerasJson(path);
    std::filesystem::remove(path);
    ASSERT_EQ(read.size(), 2u);
    // The path through them starts and ends at the recorded cameras (the file holds the
    // centre: within ulps of its size).
    const camera::CameraPath path_read = camera::CameraPath::FromViews(read, 1.0);
    EXPECT_EQ(path_read.GetDuration(), 2.0);
    for (const auto& [camera, time] : {std::pair{first, 0.0}, std::pair{second, 2.0}}) {
        const camera::PinholeCamera at = path_read.At(time);
        EXPECT_TRUE(at.GetRotation() == camera.GetRotation());
        EXPECT_LE((at.GetCenter() - camera.GetCenter()).norm(), 1e-12 * camera.GetCenter().norm());
        EXPECT_EQ(at.fy, camera.fy);
    }
    vis.ClearKeyframes();
    EXPECT_THROW(vis.SaveKeyframes(path), core::Open3DError);
}

TEST_F(VisualizerEditing, CropToTheSelectionsBoxKeepsWhatPointCloudCropKeeps) {
    visualization::Visualizer& vis = ShowScene();
    const t::geometry::PointCloud& cloud = cloud_;
    EXPECT_THROW(vis.GetSelectionBox(), core::Open3DError);
    vis.SelectSplats(50, 40, 100, 80);
    const std::vector<int64_t> selected = vis.GetSelection().at("scene");
    // The box of the selected centres, computed here from the cloud.
    const t::geometry::AxisAlignedBoundingBox want =
        cloud.SelectByIndex(selected).GetAxisAlignedBoundingBox();
    const t::geometry::OrientedBoundingBox box = vis.GetSelectionBox();
    EXPECT_TRUE(box.GetCenter() == want.GetCenter());
    EXPECT_TRUE(box.GetExtent() == want.GetExtent());
    const t::geometry::PointCloud kept = cloud.Crop(box);
    ASSERT_LT(kept.NumPoints(), cloud.NumPoints());
    ASSERT_GE(kept.NumPoints(), int64_t(selected.size()));
    EXPECT_EQ(vis.CropSplats(box), cloud.NumPoints() - kept.NumPoints());
    const rendering::GaussianSplatRenderer& splats = vis.GetScene().GetScene().GetSplatRenderer();
    EXPECT_TRUE(SameCloud(splats.GetCloud("scene"), kept));
    EXPECT_TRUE(vis.GetSelection().empty());
    ASSERT_TRUE(vis.RenderFrame());
    ASSERT_TRUE(vis.UndoEdit());
    EXPECT_TRUE(SameCloud(splats.GetCloud("scene"), cloud));
    // Inverted: what lies outside.
    vis.CropSplats(box, true);
    EXPECT_TRUE(SameCloud(splats.GetCloud("scene"), cloud.Crop(box, true)));
}

TEST_F(VisualizerEditing, TheSelectionIsDrawnAsRedPointsUntilItEnds) {
    visualization::Visualizer& vis = ShowScene();
    const int64_t before = CountRed(vis.CaptureScreenImage());
    vis.SelectSplats(50, 40, 110, 80);
    ASSERT_FALSE(vis.GetSelection().empty());
    // Hundreds of selected centres, each a 3-pixel red square where nothing hides it.
    EXPECT_GT(CountRed(vis.CaptureScreenImage()), before + 50);
    EXPECT_FALSE(
        std::count(vis.GetGeometryNames().begin(), vis.GetGeometryNames().end(), "__selection__"));
    vis.ClearSelection();
    EXPECT_EQ(CountRed(vis.CaptureScreenImage()), before);
    // The overlay's name is the viewer's, and only window objects can be removed.
    EXPECT_THROW(vis.AddGeometry("__selection__", rendering::CreateDefaultGaussianSplatScene()),
                 core::Open3DError);
    EXPECT_FALSE(vis.RemoveGeometry("__selection__"));
    EXPECT_FALSE(vis.RemoveGeometry("never added"));
}

// Pixels of the crop box's yellow (r and g high, b low; the default scene has a few).
int64_t CountYellow(const t::geometry::Image& rgb) {
    const uint8_t* p = rgb.Data<uint8_t>();
    int64_t n = 0;
    for (int64_t i = 0; i < rgb.NumPixels(); ++i) {
        const uint8_t* c = p + i * rgb.GetChannels();
        n += c[0] > 200 && c[1] > 160 && c[2] < 80;
    }
    return n;
}

TEST_F(VisualizerEditing, TheCropBoxIsDrawnAndKeepsWhatPointCloudCropKeeps) {
    visualization::Visualizer& vis = ShowScene();
    const t::geometry::PointCloud& cloud = cloud_;
    EXPECT_THROW(vis.ApplyCropBox(), core::Open3DError);
    // Without a selection the box starts at the shown clouds' bounds.
    const t::geometry::AxisAlignedBoundingBox bounds = cloud.GetAxisAlignedBoundingBox();
    EXPECT_TRUE(vis.DefaultCropBox().GetMinBound() == bounds.GetMinBound());
    EXPECT_TRUE(vis.DefaultCropBox().GetMaxBound() == bounds.GetMaxBound());
    const int64_t before = CountYellow(vis.CaptureScreenImage());
    // The middle half of the scene along each axis.
    const Eigen::Vector3d lo = bounds.GetMinBound() + 0.25 * bounds.GetExtent();
    const Eigen::Vector3d hi = bounds.GetMinBound() + 0.75 * bounds.GetExtent();
    const t::geometry::AxisAlignedBoundingBox box(lo, hi);
    vis.SetCropBox(box);
    // 12 edges of 97 points, most of them in view: hundreds of yellow pixels.
    EXPECT_GT(CountYellow(vis.CaptureScreenImage()), before + 100);
    EXPECT_FALSE(
        std::count(vis.GetGeometryNames().begin(), vis.GetGeometryNames().end(), "__crop_box__"));
    EXPECT_THROW(vis.AddGeometry("__crop_box__", cloud), core::Open3DError);
    const t::geometry::OrientedBoundingBox oriented =
        t::geometry::OrientedBoundingBox::FromAxisAligned(box);
    const t::geometry::PointCloud kept = cloud.Crop(oriented);
    ASSERT_GT(kept.NumPoints(), 0);
    ASSERT_LT(kept.NumPoints(), cloud.NumPoints());
    EXPECT_EQ(vis.ApplyCropBox(), cloud.NumPoints() - kept.NumPoints());
    const rendering::GaussianSplatRenderer& splats = vis.GetScene().GetScene().GetSplatRenderer();
    EXPECT_TRUE(SameCloud(splats.GetCloud("scene"), kept));
    EXPECT_FALSE(vis.GetCropBox().has_value());
    // The box ended with the crop: drawing it again adds its edges, cancelling takes them away.
    const int64_t cropped = CountYellow(vis.CaptureScreenImage());
    vis.SetCropBox(box);
    EXPECT_GT(CountYellow(vis.CaptureScreenImage()), cropped + 100);
    vis.SetCropBox(std::nullopt);
    EXPECT_EQ(CountYellow(vis.CaptureScreenImage()), cropped);
    ASSERT_TRUE(vis.UndoEdit());
    EXPECT_TRUE(SameCloud(splats.GetCloud("scene"), cloud));
    // "Remove inside": what lies outside stays.
    vis.SetCropBox(box);
    vis.ApplyCropBox(true);
    EXPECT_TRUE(SameCloud(splats.GetCloud("scene"), cloud.Crop(oriented, true)));
    ASSERT_TRUE(vis.UndoEdit());
    // With a selection the box starts at the selection's box.
    vis.SelectSplats(50, 40, 100, 80);
    const t::geometry::AxisAlignedBoundingBox selected =
        cloud.SelectByIndex(vis.GetSelection().at("scene")).GetAxisAlignedBoundingBox();
    EXPECT_TRUE(vis.DefaultCropBox().GetMinBound().isApprox(selected.GetMinBound(), 1e-12));
    EXPECT_TRUE(vis.DefaultCropBox().GetMaxBound().isApprox(selected.GetMaxBound(), 1e-12));
}

}  // namespace
}  // namespace tests
}  // namespace open3d
