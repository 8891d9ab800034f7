// Comparing a render with a golden PNG under tests/ (header only: suites that include it link
// open3d_io). OPEN3D_TEST_GENERATE_REFERENCE=1 writes `actual` as the golden and skips the
// test; a mismatch writes actual.png and diff.png (scaled to the largest error) to the
// test's temp folder and names it in the failure.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "TestUtility.h"
#include "open3d/t/geometry/ImageMetrics.h"
#include "open3d/t/io/ImageIO.h"

namespace open3d {
namespace tests {

/// Fails unless every value of `actual` is within `max_lsb` of the golden at
/// OPEN3D_TEST_SOURCE_DIR/`path` and at most `max_fraction_differing` of the pixels differ
/// at all.
inline void ExpectMatchesGolden(const t::geometry::Image& actual, const std::string& path,
                                double max_lsb, double max_fraction_differing = 1.0) {
    const std::string golden_path = std::string(OPEN3D_TEST_SOURCE_DIR) + "/" + path;
    const char* generate = std::getenv("OPEN3D_TEST_GENERATE_REFERENCE");
    if (generate && std::string(generate) == "1") {
        t::io::WritePNG(golden_path, actual);
        GTEST_SKIP() << "regenerated " << golden_path;
    }
    ASSERT_TRUE(std::filesystem::exists(golden_path))
        << golden_path << " is missing: run with OPEN3D_TEST_GENERATE_REFERENCE=1";
    const t::geometry::Image golden = t::io::ReadPNG(golden_path);
    ASSERT_EQ(golden.AsTensor().GetShape(), actual.AsTensor().GetShape()) << path;
    const auto m = t::geometry::ComputeImageErrorMetrics(actual, golden, 255.0, 0.0);
    const bool ok =
        m.max_abs_error <= max_lsb && m.fraction_over_threshold <= max_fraction_differing;
    if (ok) return;
    const std::string dir = TempDir();
    t::io::WritePNG(dir + "/actual.png", actual);
    t::io::WritePNG(dir + "/diff.png", t::geometry::ComputeAbsDifference(actual, golden)
                                           .ToUInt8(255.0 / std::max(1.0, m.max_abs_error)));
    ADD_FAILURE() << path << ": max error " << m.max_abs_error << " LSB, "
                  << 100 * m.fraction_over_threshold << "% of pixels differ, PSNR " << m.psnr_db
                  << " dB; actual and diff (scaled) written to " << dir;
}

}  // namespace tests
}  // namespace open3d
