// Without an X server Filament 1.9 would print "Failed to open X display" and exit the
// process; FilamentEngine throws a message that says to run under Xvfb instead.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"

namespace open3d {
namespace tests {
namespace {

TEST(FilamentEngineError, NoDisplayIsAClearError) {
    const char* display = std::getenv("DISPLAY");
    const std::string saved = display ? display : "";
    for (const char* value : {"", ":12345"}) {  // unset, and a display nobody serves
        setenv("DISPLAY", value, 1);
        EXPECT_NE(visualization::rendering::FilamentUnavailableReason().find("xvfb-run"),
                  std::string::npos);
        try {
            visualization::rendering::FilamentEngine engine;
            ADD_FAILURE() << "the engine started without an X server";
        } catch (const core::Open3DError& e) {
            EXPECT_NE(std::string(e.what()).find("xvfb-run"), std::string::npos) << e.what();
        }
    }
    if (display) {
        setenv("DISPLAY", saved.c_str(), 1);
    } else {
        unsetenv("DISPLAY");
    }
}

}  // namespace
}  // namespace tests
}  // namespace open3d
