// Shared helpers for tests: where the shared scenes are, temporary files.
#pragma once

#include <gtest/gtest.h>

#include <string>

namespace open3d {
namespace tests {

/// Folder with the shared scenes (env OPEN3D_DATA_DIR overrides the configured one).
std::string DataDir();
/// Full path of a file in the shared scenes folder, e.g. "playbot/playbot_31k.ply".
std::string DataPath(const std::string& relative);
/// True when the file exists.
bool FileExists(const std::string& path);
/// A fresh, empty folder for this test under $TMPDIR/open3d_tests (left for inspection).
std::string TempDir();

}  // namespace tests
}  // namespace open3d

/// Skips the current test with a clear message when a shared scene is absent.
#define OPEN3D_REQUIRE_DATA(relative)                                                     \
    do {                                                                                  \
        if (!::open3d::tests::FileExists(::open3d::tests::DataPath(relative))) {          \
            GTEST_SKIP() << "shared scene " << ::open3d::tests::DataPath(relative)        \
                         << " is absent (tests read ../shared/data beside the checkout)"; \
        }                                                                                 \
    } while (0)
