// The level-of-detail hierarchy's file: written and read back bit for bit, and every
// malformed file refused with the field that is wrong.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "RandomSplatCloud.h"
#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/SplatHierarchyIO.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using geometry::PointCloud;
using geometry::SplatHierarchy;

// Reading `bytes` fails with a message that contains `expected`.
void ExpectRefused(const std::string& path, const std::vector<uint8_t>& bytes,
                   const std::string& expected) {
    tests::WriteFileBytes(path, bytes);
    try {
        ReadSplatHierarchy(path);
        ADD_FAILURE() << "accepted; expected an error with '" << expected << "'";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
}

TEST(SplatHierarchyFile, RoundTripsBitForBit) {
    const std::string dir = tests::TempDir();
    for (const int degree : {0, 3}) {
        SCOPED_TRACE("SH degree " + std::to_string(degree));
        const PointCloud cloud = RandomCloud(400, degree, 17 + degree);
        const SplatHierarchy built = geometry::BuildSplatHierarchy(cloud);
        const std::string path = dir + "/scene" + std::to_string(degree) + ".lod";
        WriteSplatHierarchy(path, built);
        const SplatHierarchy read = ReadSplatHierarchy(path);
        EXPECT_EQ(read.num_leaves, built.num_leaves);
        EXPECT_NE(built.scene_fingerprint, 0u);
        EXPECT_EQ(read.scene_fingerprint, built.scene_fingerprint);
        EXPECT_EQ(read.child_offsets, built.child_offsets);
        EXPECT_EQ(read.children, built.children);
        EXPECT_TRUE(read.inner == built.inner);
        // The cut of the read hierarchy is the cut of the built one.
        geometry::SplatCutView view;
        view.world_to_camera(2, 3) = 8.0;
        view.focal_px = 600.0;
        EXPECT_EQ(geometry::CutSplatHierarchy(read, view, 60),
                  geometry::CutSplatHierarchy(built, view, 60));
    }
    // One splat: no inner node.
    const SplatHierarchy one = geometry::BuildSplatHierarchy(RandomCloud(1, 1, 3));
    WriteSplatHierarchy(dir + "/one.lod", one);
    const SplatHierarchy read = ReadSplatHierarchy(dir + "/one.lod");
    EXPECT_EQ(read.num_leaves, 1);
    EXPECT_EQ(read.NumInner(), 0);
}

TEST(SplatHierarchyFile, AFileWrittenFromTheDocumentedLayoutIsRead) {
    // tests/fuzz/seeds/two_levels_sh1.lod was written by a short Python script from the
    // layout in docs/lod.md, not by WriteSplatHierarchy: 4 leaves, inner node 0 = {0, 1},
    // inner node 1 (the root) = {4, 2, 3}, SH degree 1, inner node k at x = 0.1 k, every
    // f_rest 0.01. It is a version 1 file: no scene fingerprint.
    const SplatHierarchy h =
        ReadSplatHierarchy(std::string(OPEN3D_TEST_SOURCE_DIR) + "/fuzz/seeds/two_levels_sh1.lod");
    EXPECT_EQ(h.num_leaves, 4);
    EXPECT_EQ(h.scene_fingerprint, 0u);
    EXPECT_EQ(h.child_offsets, (std::vector<int64_t>{0, 2, 5}));
    EXPECT_EQ(h.children, (std::vector<int64_t>{0, 1, 4, 2, 3}));
    ASSERT_EQ(h.inner.NumPoints(), 2);
    EXPECT_EQ(h.inner.GaussianSplatGetSHOrder(), 1);
    EXPECT_EQ(h.inner.GetPointPositions().Data<float>()[3], 0.1f);
    EXPECT_EQ(h.inner.GetPointAttr("f_rest").Data<float>()[17], 0.01f);
}

TEST(SplatHierarchyFile, MalformedFilesAreRefusedNamingTheField) {
    const std::string dir = tests::TempDir();
    const SplatHierarchy built = geometry::BuildSplatHierarchy(RandomCloud(50, 1, 5));
    const std::string good = dir + "/good.lod";
    WriteSplatHierarchy(good, built);
    const std::vector<uint8_t> bytes = tests::ReadFileBytes(good);
    ASSERT_GT(bytes.size(), 64u);
    const std::string bad = dir + "/bad.lod";
    const auto patched = [&](size_t at, const void* value, size_t size) {
        std::vector<uint8_t> copy = bytes;
        std::memcpy(copy.data() + at, value, size);
        return copy;
    };
    ExpectRefused(bad, {bytes.begin(), bytes.begin() + 20}, "magic");
    ExpectRefused(bad, patched(0, "PLYPLYPL", 8), "magic");
    const uint32_t version = 3, degree = 4;
    ExpectRefused(bad, patched(8, &version, 4), "version 3");
    ExpectRefused(bad, patched(12, &degree, 4), "sh_degree 4");
    ExpectRefused(bad, {bytes.begin(), bytes.end() - 4}, "the file has");
    std::vector<uint8_t> longer = bytes;
    longer.push_back(0);
    ExpectRefused(bad, longer, "the file has");
    const int64_t huge = int64_t(1) << 40;
    ExpectRefused(bad, patched(24, &huge, 8), "do not fit");
    // The first child of inner node 0 (after the header of version 2 and the offsets).
    const size_t first_child = 48 + 8 * (built.NumInner() + 1);
    const int64_t outside = built.num_leaves + built.NumInner();
    ExpectRefused(bad, patched(first_child, &outside, 8), "is not a node built before it");
    const int64_t twice = built.children[1];  // the first child repeats the second
    ExpectRefused(bad, patched(first_child, &twice, 8), "has two parents");
    // The documented two-level file with offsets {0, 6, 5} for its 5 children: node 0's
    // count (6) fits 2..8 but runs past the children, node 1's is -1. Reading node 0's
    // children before checking node 1 read past the array (fuzz_splat_hierarchy_reader).
    std::vector<uint8_t> two_levels = tests::ReadFileBytes(std::string(OPEN3D_TEST_SOURCE_DIR) +
                                                           "/fuzz/seeds/two_levels_sh1.lod");
    const int64_t past_the_end = 6;
    std::memcpy(two_levels.data() + 40 + 8, &past_the_end, 8);
    ExpectRefused(bad, two_levels, "inner node 1 has -1 children");
    const float nan = std::nanf("");
    ExpectRefused(bad, patched(bytes.size() - 4, &nan, 4), "non-finite f_rest");
    EXPECT_THROW(ReadSplatHierarchy(dir + "/missing.lod"), core::Open3DError);
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
