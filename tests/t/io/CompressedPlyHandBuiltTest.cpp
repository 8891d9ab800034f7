// PlayCanvas compressed PLY files built by hand: the bit layout of the packed words and the
// SH element pinned, malformed files refused with clean errors, trailing bytes reported.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "IoTestHelpers.h"
#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using core::Tensor;
using geometry::kSH_C0;
using geometry::PointCloud;

// A compressed PLY assembled byte by byte: header lines, then the rows of each element.
struct HandFile {
    std::vector<std::string> header = {"ply", "format binary_little_endian 1.0"};
    std::string data;
    void Line(const std::string& line) { header.push_back(line); }
    void Floats(std::initializer_list<float> values) {
        for (float v : values) data.append(reinterpret_cast<const char*>(&v), 4);
    }
    void Words(std::initializer_list<uint32_t> values) {
        for (uint32_t v : values) data.append(reinterpret_cast<const char*>(&v), 4);
    }
    void Write(const std::string& path) const {
        std::ofstream out(path, std::ios::binary);
        for (const auto& line : header) out << line << "\n";
        out << "end_header\n" << data;
    }
};

const char* const kChunkProps[18] = {
    "min_x",       "min_y",       "min_z",       "max_x",       "max_y",       "max_z",
    "min_scale_x", "min_scale_y", "min_scale_z", "max_scale_x", "max_scale_y", "max_scale_z",
    "min_r",       "min_g",       "min_b",       "max_r",       "max_g",       "max_b"};
const char* const kVertexProps[4] = {"packed_position", "packed_rotation", "packed_scale",
                                     "packed_color"};

// Two splats in one chunk, with or without colour bounds. Positions: x in [0, 2047] and z in
// [0, 2047] over 11 bits, y in [0, 1023] over 10 bits, so the decoded value is the code.
HandFile TwoSplats(bool colour_bounds) {
    HandFile f;
    f.Line("comment hand-built");
    f.Line("element chunk 1");
    for (int k = 0; k < (colour_bounds ? 18 : 12); ++k) {
        f.Line(std::string("property float ") + kChunkProps[k]);
    }
    f.Line("element vertex 2");
    for (const char* name : kVertexProps) f.Line(std::string("property uint ") + name);
    f.Floats({0, 0, 0, 2047, 1023, 2047, 0, 0, -2, 2047, 1023, -2});
    if (colour_bounds) f.Floats({0.25f, 0.5f, 0, 0.75f, 1, 1});
    // Splat 0: position (5, 7, 9); log-scales (1, 2, -2); rotation: largest is rot_2, stored
    // codes 1023, 0, 512 for rot_0, rot_1, rot_3; colour codes (255, 0, 51), alpha 51.
    // Splat 1: position (2047, 1023, 0); log-scales (0, 0, -2); rotation: largest rot_1,
    // codes 512 for the others; colour (0, 255, 255), alpha 0 / 255 for the two extremes.
    f.Words({(5u << 21) | (7u << 11) | 9u, (2u << 30) | (1023u << 20) | (0u << 10) | 512u,
             (1u << 21) | (2u << 11) | 0u, (255u << 24) | (0u << 16) | (51u << 8) | 51u});
    f.Words({(2047u << 21) | (1023u << 11), (1u << 30) | (512u << 20) | (512u << 10) | 512u, 0u,
             (0u << 24) | (255u << 16) | (255u << 8) | 255u});
    return f;
}

TEST(CompressedPly, HandBuiltFilePinsTheBitLayout) {
    const std::string dir = tests::TempDir();
    for (bool colour_bounds : {true, false}) {
        SCOPED_TRACE(colour_bounds ? "18 chunk properties" : "12 chunk properties (older files)");
        const std::string path = dir + "/hand.compressed.ply";
        TwoSplats(colour_bounds).Write(path);
        const PointCloud c = ReadCloud(path);
        ASSERT_EQ(c.NumPoints(), 2);
        const float* p = FloatsOf(c, "positions");
        EXPECT_FLOAT_EQ(p[0], 5);
        EXPECT_FLOAT_EQ(p[1], 7);
        EXPECT_FLOAT_EQ(p[2], 9);
        EXPECT_FLOAT_EQ(p[3], 2047);
        EXPECT_FLOAT_EQ(p[4], 1023);
        EXPECT_FLOAT_EQ(p[5], 0);
        const float* s = FloatsOf(c, "scale");
        EXPECT_FLOAT_EQ(s[0], std::exp(1.0f));
        EXPECT_FLOAT_EQ(s[1], std::exp(2.0f));
        EXPECT_FLOAT_EQ(s[2], std::exp(-2.0f));
        EXPECT_FLOAT_EQ(s[3], 1.0f);
        const float* q = FloatsOf(c, "rot");
        const double r = std::sqrt(0.5), tiny = (512.0 / 1023 - 0.5) * std::sqrt(2.0);
        EXPECT_FLOAT_EQ(q[0], r);     // code 1023
        EXPECT_FLOAT_EQ(q[1], -r);    // code 0
        EXPECT_FLOAT_EQ(q[2], 0.0f);  // sqrt(max(0, 1 - (1/2 + 1/2 + tiny^2)))
        EXPECT_FLOAT_EQ(q[3], tiny);
        EXPECT_FLOAT_EQ(q[4], tiny);
        EXPECT_FLOAT_EQ(q[5], std::sqrt(1 - 3 * tiny * tiny));
        EXPECT_FLOAT_EQ(q[6], tiny);
        EXPECT_FLOAT_EQ(q[7], tiny);
        // Colour: lerp(min, max, code / 255) with bounds (0.25, 0.5, 0) .. (0.75, 1, 1),
        // code / 255 without.
        const float* dc = FloatsOf(c, "f_dc");
        auto f_dc = [](double colour) { return float((colour - 0.5) / kSH_C0); };
        EXPECT_FLOAT_EQ(dc[0], f_dc(colour_bounds ? 0.75 : 1.0));
        EXPECT_FLOAT_EQ(dc[1], f_dc(colour_bounds ? 0.5 : 0.0));
        EXPECT_FLOAT_EQ(dc[2], f_dc(colour_bounds ? 0.2 : 0.2));
        EXPECT_FLOAT_EQ(dc[3], f_dc(colour_bounds ? 0.25 : 0.0));
        EXPECT_FLOAT_EQ(dc[4], f_dc(1.0));
        EXPECT_FLOAT_EQ(dc[5], f_dc(1.0));
        const float* o = FloatsOf(c, "opacity");
        EXPECT_FLOAT_EQ(o[0], -std::log(4.0f));  // alpha 51 / 255 = 0.2
        EXPECT_FLOAT_EQ(o[1], 40.0f);            // alpha 255: the engine's +40
    }
}

TEST(CompressedPly, HandBuiltSHElement) {
    // One splat, SH degree 1: f_rest_0..8 = bytes 0, 1, 127, 128, 254, 255, 10, 20, 30;
    // the element's properties are listed out of order to check lookup by name.
    HandFile f = TwoSplats(true);
    *std::find(f.header.begin(), f.header.end(), "element vertex 2") = "element vertex 1";
    f.data.resize(18 * 4 + 16);  // drop splat 1
    const int order[9] = {8, 0, 1, 2, 3, 4, 5, 6, 7};
    const uint8_t bytes[9] = {0, 1, 127, 128, 254, 255, 10, 20, 30};
    f.Line("element sh 1");
    for (int k : order) f.Line("property uchar f_rest_" + std::to_string(k));
    for (int k : order) f.data.push_back(static_cast<char>(bytes[k]));
    const std::string path = tests::TempDir() + "/sh.compressed.ply";
    f.Write(path);
    const PointCloud c = ReadCloud(path);
    ASSERT_EQ(c.GaussianSplatGetSHOrder(), 1);
    const float* rest =
        FloatsOf(c, "f_rest");  // [1, 3, 3]: f_rest_[ch * 3 + k] -> rest[k * 3 + ch]
    auto expect = [](uint8_t b) {
        return b == 0 ? -4.0f : b == 255 ? 4.0f : float(((b + 0.5) / 256 - 0.5) * 8);
    };
    for (int ch = 0; ch < 3; ++ch) {
        for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(rest[k * 3 + ch], expect(bytes[ch * 3 + k]));
    }
}

TEST(CompressedPly, MalformedFilesGiveCleanErrors) {
    const std::string dir = tests::TempDir();
    const std::string path = dir + "/bad.compressed.ply";
    auto vertex_line = [](HandFile& f) -> std::string& {
        return *std::find(f.header.begin(), f.header.end(), std::string("element vertex 2"));
    };
    {  // more vertices than the file holds
        HandFile f = TwoSplats(true);
        vertex_line(f) = "element vertex 1000";
        f.Write(path);
        ExpectReadError(path, {"element 'vertex' declares 1000 rows"});
    }
    {  // truncated inside the vertex rows
        HandFile f = TwoSplats(true);
        f.data.resize(f.data.size() - 3);
        f.Write(path);
        ExpectReadError(path, {"element 'vertex'", "truncated"});
    }
    {  // chunk count is not ceil(vertices / 256)
        HandFile f = TwoSplats(true);
        f.header[3] = "element chunk 2";
        f.data.insert(0, std::string(18 * 4, '\0'));
        f.Write(path);
        ExpectReadError(path, {"element 'chunk' has 2 rows", "ceil(2 / 256) = 1"});
    }
    {  // a missing vertex property
        HandFile f = TwoSplats(true);
        auto it = std::find(f.header.begin(), f.header.end(), "property uint packed_rotation");
        *it = "property uint packed_rotation_renamed";
        f.Write(path);
        ExpectReadError(path, {"'packed_rotation'", "element 'vertex'"});
    }
    {  // a missing chunk property
        HandFile f = TwoSplats(false);
        auto it = std::find(f.header.begin(), f.header.end(), "property float min_scale_y");
        *it = "property float min_scale_q";
        f.Write(path);
        ExpectReadError(path, {"'min_scale_y'", "element 'chunk'"});
    }
    {  // some colour bounds only
        HandFile f = TwoSplats(true);
        auto it = std::find(f.header.begin(), f.header.end(), "property float max_b");
        *it = "property float max_blue";
        f.Write(path);
        ExpectReadError(path, {"'max_b'", "element 'chunk'"});
    }
    {  // a property of the wrong type
        HandFile f = TwoSplats(true);
        auto it = std::find(f.header.begin(), f.header.end(), "property uint packed_color");
        *it = "property float packed_color";
        f.Write(path);
        ExpectReadError(path, {"'packed_color'", "element 'vertex'", "is float"});
    }
    {  // an sh element with a count of properties no SH degree has
        HandFile f = TwoSplats(true);
        f.Line("element sh 2");
        for (int k = 0; k < 10; ++k) f.Line("property uchar f_rest_" + std::to_string(k));
        f.data += std::string(20, '\x80');
        f.Write(path);
        ExpectReadError(path, {"element 'sh' has 10 f_rest properties"});
    }
    {  // an sh element with fewer rows than vertices
        HandFile f = TwoSplats(true);
        f.Line("element sh 1");
        for (int k = 0; k < 9; ++k) f.Line("property uchar f_rest_" + std::to_string(k));
        f.data += std::string(9, '\x80');
        f.Write(path);
        ExpectReadError(path, {"element 'sh' has 1 rows", "'vertex' has 2"});
    }
    {  // sh properties with a gap
        HandFile f = TwoSplats(true);
        f.Line("element sh 2");
        for (int k = 0; k < 9; ++k) f.Line("property uchar f_rest_" + std::to_string(k + (k > 4)));
        f.data += std::string(18, '\x80');
        f.Write(path);
        ExpectReadError(path, {"element 'sh'", "not contiguous"});
    }
    {  // ASCII
        HandFile f = TwoSplats(true);
        f.header[1] = "format ascii 1.0";
        f.Write(path);
        ExpectReadError(path, {"binary_little_endian"});
    }
    {  // no vertex element
        HandFile f;
        f.Line("element chunk 0");
        for (const char* name : kChunkProps) f.Line(std::string("property float ") + name);
        f.Write(path);
        ExpectReadError(path, {"no 'vertex' element"});
    }
    {  // a list property in an element
        HandFile f = TwoSplats(true);
        f.Line("element extra 1");
        f.Line("property list uchar int indices");
        f.Write(path);
        ExpectReadError(path, {"element 'extra'", "list"});
    }
}

TEST(CompressedPly, TrailingBytesAreReportedAndOtherElementsSkipped) {
    HandFile f = TwoSplats(true);
    f.Line("element camera 2");
    f.Line("property double fx");
    f.data += std::string(16, '\0');
    f.data += "trailing";
    const std::string path = tests::TempDir() + "/extra.compressed.ply";
    f.Write(path);
    PointCloud cloud;
    const ReadPointCloudReport report = ReadPointCloud(path, cloud);
    EXPECT_EQ(cloud.NumPoints(), 2);
    EXPECT_EQ(report.trailing_bytes, 8);
}

// Regenerates the compressed PLY fuzz seeds (run with --gtest_also_run_disabled_tests):
// two chunks without SH, one chunk with SH degree 3, and a hand-built file without colour
// bounds; each under 8 KB.

TEST(CompressedPly, EmptyCloud) {
    PointCloud in(Tensor::Empty({0, 3}, core::Dtype::Float32));
    for (auto [name, width] : {std::pair{"scale", 3}, std::pair{"rot", 4}, std::pair{"opacity", 1},
                               std::pair{"f_dc", 3}}) {
        in.SetPointAttr(name, Tensor::Empty({0, width}, core::Dtype::Float32));
    }
    const std::string path = tests::TempDir() + "/empty.compressed.ply";
    WritePointCloud(path, in);
    EXPECT_EQ(ReadCloud(path).NumPoints(), 0);
}

// Regenerates the hand-built fuzz seed (run with --gtest_also_run_disabled_tests).
TEST(CompressedPlyHandBuilt, DISABLED_WriteFuzzSeed) {
    TwoSplats(false).Write(std::string(OPEN3D_TEST_SOURCE_DIR) +
                           "/fuzz/seeds/no_colour_bounds.compressed.ply");
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
