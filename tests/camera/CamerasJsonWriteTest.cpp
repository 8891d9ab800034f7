// Writing cameras.json (CamerasJsonText / WriteCamerasJson): what the reader gives back, for
// the shared scene's views and for timed keyframes, and the refusal of what the format cannot
// hold (an off-centre principal point).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"

namespace open3d {
namespace tests {
namespace {

using camera::CameraView;

void ExpectSameViews(const std::vector<CameraView>& a, const std::vector<CameraView>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
        SCOPED_TRACE("view " + std::to_string(i));
        EXPECT_EQ(a[i].id, b[i].id);
        EXPECT_EQ(a[i].img_name, b[i].img_name);
        EXPECT_EQ(a[i].time, b[i].time);
        const camera::PinholeCamera& p = a[i].camera;
        const camera::PinholeCamera& q = b[i].camera;
        EXPECT_EQ(p.width, q.width);
        EXPECT_EQ(p.height, q.height);
        EXPECT_EQ(p.fx, q.fx);
        EXPECT_EQ(p.fy, q.fy);
        EXPECT_EQ(p.cx, q.cx);
        EXPECT_EQ(p.cy, q.cy);
        // The rotation is written as read (its transpose, exactly); the file holds the centre,
        // -R^T t, whose rounding moves it by ulps of the centre's size.
        EXPECT_TRUE(p.GetRotation() == q.GetRotation());
        EXPECT_LE((p.GetCenter() - q.GetCenter()).norm(), 1e-12 * (1.0 + p.GetCenter().norm()));
    }
}

TEST(CamerasJsonWrite, TheSharedViewsReadBackAsRead) {
    OPEN3D_REQUIRE_DATA("playbot/cameras.json");
    const std::vector<CameraView> views = camera::ReadCamerasJson(DataPath("playbot/cameras.json"));
    ASSERT_GT(views.size(), 10u);
    ExpectSameViews(views, camera::ParseCamerasJson(camera::CamerasJsonText(views), "written"));
}

TEST(CamerasJsonWrite, TimesAreWrittenWhereSetAndTheFileAppearsWhole) {
    std::vector<CameraView> views(2);
    camera::LookAtCamera look;
    look.eye = Eigen::Vector3d(1, 2, 3);
    views[0].camera = camera::PinholeCamera::FromLookAt(look, 64, 48);
    views[0].time = 0.25;
    look.eye = Eigen::Vector3d(-1, 0.5, 4);
    views[1].id = 1;
    views[1].img_name = "second";
    views[1].camera = camera::PinholeCamera::FromLookAt(look, 64, 48);
    const std::string path = (std::filesystem::path(TempDir()) / "cameras_write.json").string();
    camera::WriteCamerasJson(path, views);
    EXPECT_FALSE(std::filesystem::exists(path + ".partial"));
    const std::vector<CameraView> read = camera::ReadCamerasJson(path);
    std::filesystem::remove(path);
    ExpectSameViews(views, read);
    ASSERT_TRUE(read[0].time.has_value());
    EXPECT_FALSE(read[1].time.has_value());
}

TEST(CamerasJsonWrite, AnOffCentrePrincipalPointIsRefused) {
    std::vector<CameraView> views(1);
    views[0].camera = camera::PinholeCamera::FromLookAt(camera::LookAtCamera{}, 64, 48);
    views[0].camera.cx += 0.5;
    EXPECT_THROW(
        {
            try {
                camera::CamerasJsonText(views);
            } catch (const core::Open3DError& e) {
                EXPECT_NE(std::string(e.what()).find("entry 0: principal point"), std::string::npos)
                    << e.what();
                throw;
            }
        },
        core::Open3DError);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
