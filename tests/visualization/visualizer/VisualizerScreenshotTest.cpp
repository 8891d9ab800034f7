// The viewer's screenshots: the P key writes what the window shows, requests before a frame
// make one shot, and a folder that cannot be written is a message, not an end.
#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "TestUtility.h"
#include "open3d/t/io/ImageIO.h"
#include "open3d/visualization/visualizer/Visualizer.h"
#include "visualization/visualizer/VisualizerTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using visualization::Visualizer;

TEST_F(VisualizerTest, ScreenshotKeyWritesThePicture) {
    Visualizer& vis = MakeVisualizer();
    AddWallAndSphere(vis);
    const std::string dir = TempDir();
    vis.SetScreenshotDir(dir);
    PressKey(vis, GLFW_KEY_P);
    ASSERT_TRUE(vis.RenderFrame());
    const std::string path = dir + "/screenshot_0000.png";
    ASSERT_EQ(vis.GetLastScreenshotPath(), path);
    ASSERT_TRUE(std::filesystem::exists(path));
    const t::geometry::Image saved = t::io::ReadPNG(path);
    const t::geometry::Image shown = vis.CaptureScreenImage();
    ASSERT_EQ(saved.GetChannels(), 3);
    ASSERT_EQ(saved.NumPixels(), shown.NumPixels());
    EXPECT_EQ(MeanAbsDiff(saved, shown, 0, 0, 240, 160), 0.0);
    EXPECT_FALSE(std::filesystem::exists(path + ".part"));
}

// Requests before a frame is drawn (P pressed twice during a load) make one shot and use one
// number: the number is taken when the file is written.
TEST_F(VisualizerTest, ScreenshotRequestsBeforeAFrameMakeOneShot) {
    Visualizer& vis = MakeVisualizer();
    AddWallAndSphere(vis);
    const std::string dir = TempDir();
    vis.SetScreenshotDir(dir);
    const std::string first = vis.RequestScreenshot();
    EXPECT_EQ(vis.RequestScreenshot(), first);
    EXPECT_TRUE(vis.HasPendingScreenshot());
    ASSERT_TRUE(vis.RenderFrame());
    EXPECT_FALSE(vis.HasPendingScreenshot());
    EXPECT_EQ(first, dir + "/screenshot_0000.png");
    EXPECT_EQ(vis.GetLastScreenshotPath(), first);
    // The shot's frame drew the new splats (the panel shows their numbers, not 0).
    EXPECT_GT(vis.GetLastFrame().splat_stats.num_visible, 0);
    EXPECT_EQ(vis.RequestScreenshot(), dir + "/screenshot_0001.png");
}

// A screenshot that cannot be written is a message; the viewer goes on and a later one into
// a good folder works.
TEST_F(VisualizerTest, ScreenshotIntoABadFolderIsAMessage) {
    Visualizer& vis = MakeVisualizer();
    AddWallAndSphere(vis);
    const std::string dir = TempDir();
    const std::string file = dir + "/a_file";
    std::ofstream(file) << "not a folder";
    vis.SetScreenshotDir(file + "/shots");
    vis.RequestScreenshot();
    ASSERT_NO_THROW(vis.RenderFrame());
    EXPECT_NE(vis.GetLastScreenshotError().find("Screenshot not saved"), std::string::npos);
    EXPECT_NE(vis.GetLastScreenshotError().find("a_file"), std::string::npos)
        << vis.GetLastScreenshotError();
    EXPECT_TRUE(vis.GetLastScreenshotPath().empty());
    vis.SetScreenshotDir(dir);
    const std::string path = vis.RequestScreenshot();
    ASSERT_TRUE(vis.RenderFrame());
    EXPECT_TRUE(vis.GetLastScreenshotError().empty());
    EXPECT_EQ(vis.GetLastScreenshotPath(), path);
    EXPECT_TRUE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace tests
}  // namespace open3d
