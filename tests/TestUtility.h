// Shared helpers for tests: where the shared scenes are, temporary files, and the one rule
// for tests that cannot run here (skip locally, fail in CI).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "open3d/core/Exception.h"

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

/// The bytes of a file (empty when it cannot be read).
std::vector<uint8_t> ReadFileBytes(const std::string& path);
/// Writes `bytes` as the whole file at `path`.
void WriteFileBytes(const std::string& path, const std::vector<uint8_t>& bytes);
/// Appends `value` little-endian (files assembled byte by byte as their specs lay them out).
void AppendU32(std::vector<uint8_t>& bytes, uint32_t value);
void AppendU64(std::vector<uint8_t>& bytes, uint64_t value);
/// The warnings (core::LogWarning) logged while `call` runs, in order; the previous log sink
/// is back afterwards, also when `call` throws.
std::vector<std::string> CaptureWarnings(const std::function<void()>& call);
/// True in CI (environment CI=true): there a test that lacks an X display, a Vulkan device,
/// a tool or a shared scene fails instead of skipping, so the suite cannot pass by skipping.
bool SkipsAreFailures();

/// Runs `call`, which must throw core::Open3DError with `part` in its message.
template <typename Call>
void ExpectErrorContaining(const Call& call, const std::string& part) {
    try {
        call();
        ADD_FAILURE() << "accepted; expected an error with '" << part << "'";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
}

/// Sets an environment variable for the scope of a test, then restores it (or unsets it).
class ScopedEnvironment {
public:
    ScopedEnvironment(const std::string& name, const std::string& value);
    ~ScopedEnvironment();
    ScopedEnvironment(const ScopedEnvironment&) = delete;
    ScopedEnvironment& operator=(const ScopedEnvironment&) = delete;

private:
    std::string name_, saved_;
    bool was_set_ = false;
};

}  // namespace tests
}  // namespace open3d

/// Ends the current test (or SetUp) because something it needs is unavailable: a skip
/// with `reason` (a std::string) normally, a failure with it in CI (SkipsAreFailures).
/// Every skip for a missing display, device, tool or shared scene goes through here;
/// scripts/test.sh lists the skips of a local run.
#define OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE(reason)                                        \
    do {                                                                                    \
        const std::string open3d_unavailable_reason_ = (reason);                            \
        if (::open3d::tests::SkipsAreFailures()) {                                          \
            FAIL() << "CI=true, so this test may not skip: " << open3d_unavailable_reason_; \
        }                                                                                   \
        GTEST_SKIP() << open3d_unavailable_reason_;                                         \
    } while (0)

/// Skips (fails in CI) the current test with a clear message when a shared scene is absent.
#define OPEN3D_REQUIRE_DATA(relative)                                            \
    do {                                                                         \
        if (!::open3d::tests::FileExists(::open3d::tests::DataPath(relative))) { \
            OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE(                                \
                "shared scene " + ::open3d::tests::DataPath(relative) +          \
                " is absent (tests read ../shared/data beside the checkout)");   \
        }                                                                        \
    } while (0)
