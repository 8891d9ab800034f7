// Without an X server Filament 1.9's GLX backend would print "Failed to open X display" and
// exit the process; FilamentEngine on GLX throws a message that says to run under Xvfb
// instead, and the automatic platform starts headless on EGL.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"

namespace open3d {
namespace tests {
namespace {

namespace rendering = visualization::rendering;

TEST(FilamentEngineError, NoDisplayIsAClearErrorOnGlx) {
    for (const char* value : {"", ":12345"}) {  // empty (as unset), and a display nobody serves
        ScopedEnvironment display("DISPLAY", value);
        EXPECT_NE(
            rendering::FilamentUnavailableReason(rendering::GlPlatform::kGlx).find("xvfb-run"),
            std::string::npos);
        ExpectErrorContaining([] { rendering::FilamentEngine engine(rendering::GlPlatform::kGlx); },
                              "xvfb-run");
    }
}

TEST(FilamentEngineError, PlatformVariableIsChecked) {
    ScopedEnvironment platform("OPEN3D_FILAMENT_PLATFORM", "wayland");
    EXPECT_NE(rendering::FilamentUnavailableReason().find("OPEN3D_FILAMENT_PLATFORM"),
              std::string::npos);
    EXPECT_THROW(rendering::FilamentEngine engine, core::Open3DError);
}

TEST(FilamentEngineError, WithoutDisplayTheAutomaticPlatformIsEgl) {
    ScopedEnvironment display("DISPLAY", "");
    ScopedEnvironment platform("OPEN3D_FILAMENT_PLATFORM", "");
    EXPECT_EQ(rendering::ResolveGlPlatform(rendering::GlPlatform::kAuto),
              rendering::GlPlatform::kEgl);
    const std::string reason = rendering::FilamentUnavailableReason();
    if (!reason.empty()) OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE(reason);
    rendering::FilamentEngine engine;
    EXPECT_EQ(engine.GetPlatform(), rendering::GlPlatform::kEgl);
    EXPECT_EQ(engine.GetSharedContextWindow(), nullptr);
    EXPECT_NE(engine.DescribePlatform().find("EGL"), std::string::npos);
    // Our context is current and loads the GL entry points (GL_VERSION 4.5 or later).
    EXPECT_NE(engine.GetGl().Describe().find("4."), std::string::npos) << engine.GetGl().Describe();
}

}  // namespace
}  // namespace tests
}  // namespace open3d
