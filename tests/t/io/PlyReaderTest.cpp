// The PLY reader against files written byte by byte here: layouts, encodings, and every
// kind of bad input with its error message.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include "IoTestHelpers.h"
#include "PlyTestFiles.h"
#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using core::Open3DError;
using geometry::PointCloud;
using tests::GaussianPropertyNames;
using tests::PlausibleRows;
using tests::WriteFloatPly;
using tests::WriteText;

TEST(PlyReader, ReadsEveryDegreeWithDerivedValues) {
    const std::string dir = tests::TempDir();
    for (int degree = 0; degree <= 3; ++degree) {
        const std::string path = dir + "/d" + std::to_string(degree) + ".ply";
        WriteFloatPly(path, GaussianPropertyNames(degree), PlausibleRows(degree, 5));
        PointCloud cloud;
        const auto report = ReadPointCloud(path, cloud);
        EXPECT_EQ(report.num_points, 5);
        ASSERT_TRUE(cloud.IsGaussianSplat());
        EXPECT_EQ(cloud.GaussianSplatGetSHOrder(), degree);
        const float* s = cloud.GetPointAttr("scale").Data<float>();
        // exp in double rounded to float, so exactly expf-correctly-rounded values.
        EXPECT_EQ(s[3 * 4 + 0], static_cast<float>(std::exp(-2.0)));
        EXPECT_EQ(s[3 * 4 + 2], static_cast<float>(std::exp(-4.0)));
        EXPECT_EQ(cloud.GetPointPositions().Data<float>()[3 * 4 + 2], 12.0f);
        if (degree > 0) {
            // f_rest_[c * Nc + k] lands at [k][c]; PlausibleRow sets 0.01 * strlen(name).
            const int nc = geometry::NumSHRestCoeffs(degree);
            const float* rest = cloud.GetPointAttr("f_rest").Data<float>();
            const int k = nc - 1, c = 2;
            const std::string name = "f_rest_" + std::to_string(c * nc + k);
            EXPECT_EQ(rest[k * 3 + c], 0.01f * float(name.size()));
        }
    }
}

TEST(PlyReader, PropertyOrderTypesEncodingsAndExtrasAreFree) {
    // Properties shuffled, mixed types (double, uchar, int), an extra property and an extra
    // element after the vertices, in ASCII and big endian: all must read the same values.
    const std::string dir = tests::TempDir();
    const std::string props =
        "property double rot_1\nproperty float opacity\nproperty uchar extra\n"
        "property float f_dc_2\nproperty int x\nproperty float scale_2\nproperty float rot_0\n"
        "property float y\nproperty float f_dc_0\nproperty float scale_0\nproperty float z\n"
        "property float rot_3\nproperty float f_dc_1\nproperty float scale_1\n"
        "property float rot_2\n";
    WriteText(dir + "/a.ply", "ply\nformat ascii 1.0\ncomment hi\nelement vertex 2\n" + props +
                                  "element face 1\nproperty list uchar int vertex_indices\n"
                                  "end_header\n"
                                  "0 0.5 7 0.1 3 -1 2 4 0.2 -1 5 0 0.3 -1 0\n"
                                  "0 -0.5 9 0.1 -6 -1 0 4 0.2 -1 5 0 0.3 -1 2\n"
                                  "3 0 1 2\n");
    PointCloud cloud;
    ReadPointCloud(dir + "/a.ply", cloud);
    ASSERT_EQ(cloud.NumPoints(), 2);
    const float* p = cloud.GetPointPositions().Data<float>();
    EXPECT_EQ(p[0], 3.0f);
    EXPECT_EQ(p[1], 4.0f);
    EXPECT_EQ(p[2], 5.0f);
    EXPECT_EQ(p[3], -6.0f);
    // Second splat has rot_2 = 2 and the rest 0: normalised to (0, 0, 1, 0).
    const float* q = cloud.GetPointAttr("rot").Data<float>();
    EXPECT_EQ(q[4], 0.0f);
    EXPECT_EQ(q[6], 1.0f);
    EXPECT_EQ(cloud.GetPointAttr("opacity").Data<float>()[1], -0.5f);
    EXPECT_EQ(cloud.GetPointAttr("f_dc").Data<float>()[2], 0.1f);

    // Big endian with a double column.
    std::ofstream out(dir + "/b.ply", std::ios::binary);
    out << "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty double x\n"
           "property float y\nproperty float z\nend_header\n";
    auto put_be = [&](const void* v, int size) {
        const char* b = static_cast<const char*>(v);
        for (int i = size - 1; i >= 0; --i) out.put(b[i]);
    };
    const double x = -1.25;
    const float y = 2.5f, z = 1e-3f;
    put_be(&x, 8);
    put_be(&y, 4);
    put_be(&z, 4);
    out.close();
    PointCloud plain;
    ReadPointCloud(dir + "/b.ply", plain);
    EXPECT_FALSE(plain.IsGaussianSplat());
    const float* bp = plain.GetPointPositions().Data<float>();
    EXPECT_EQ(bp[0], -1.25f);
    EXPECT_EQ(bp[1], 2.5f);
    EXPECT_EQ(bp[2], 1e-3f);
}

TEST(PlyReader, TruncatedData) {
    const std::string path = tests::TempDir() + "/t.ply";
    auto rows = PlausibleRows(1, 4);
    rows.resize(rows.size() - 3);  // the last vertex is cut short
    WriteFloatPly(path, GaussianPropertyNames(1), rows, 4);
    ExpectReadError(path, {"declares 4 vertices", "truncated"});
}

TEST(PlyReader, HeaderCountLargerThanData) {
    const std::string path = tests::TempDir() + "/c.ply";
    WriteFloatPly(path, GaussianPropertyNames(0), PlausibleRows(0, 3), 10);
    ExpectReadError(path, {"declares 10 vertices", "at most 3"});
}

TEST(PlyReader, HugeCountIsRefusedBeforeAllocating) {
    // 10^15 vertices of 68 bytes would be 68 PB: the reader must refuse from the file size.
    const std::string path = tests::TempDir() + "/h.ply";
    WriteFloatPly(path, GaussianPropertyNames(0), PlausibleRows(0, 1), 1000000000000000LL);
    ExpectReadError(path, {"declares 1000000000000000 vertices"});
    const std::string ascii = tests::TempDir() + "/ha.ply";
    WriteText(ascii,
              "ply\nformat ascii 1.0\nelement vertex 999999999999\nproperty float x\n"
              "property float y\nproperty float z\nend_header\n1 2 3\n");
    ExpectReadError(ascii, {"declares 999999999999 vertices"});
}

TEST(PlyReader, MissingRequiredProperty) {
    const std::string path = tests::TempDir() + "/m.ply";
    auto names = GaussianPropertyNames(0);
    names.back() = "rot_9";  // rot_3 missing
    WriteFloatPly(path, names, PlausibleRows(0, 2));
    ExpectReadError(path, {"missing required property 'rot_3'"});
    const std::string no_z = tests::TempDir() + "/z.ply";
    WriteFloatPly(no_z, {"x", "y"}, {1, 2});
    ExpectReadError(no_z, {"missing required property 'z'"});
}

TEST(PlyReader, BadSHCount) {
    const std::string path = tests::TempDir() + "/sh.ply";
    auto names = GaussianPropertyNames(0);
    for (int k = 0; k < 5; ++k) names.push_back("f_rest_" + std::to_string(k));
    WriteFloatPly(path, names, std::vector<float>(names.size(), 1.0f));
    ExpectReadError(path, {"5 f_rest properties"});
    auto gap = GaussianPropertyNames(0);
    gap.push_back("f_rest_0");
    gap.push_back("f_rest_2");
    WriteFloatPly(path, gap, std::vector<float>(gap.size(), 1.0f));
    ExpectReadError(path, {"not contiguous", "f_rest_1"});
}

TEST(PlyReader, UnsupportedPropertyType) {
    const std::string path = tests::TempDir() + "/u.ply";
    WriteText(path,
              "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty half x\n"
              "end_header\n");
    ExpectReadError(path, {"unsupported property type 'half'", "line 4"});
}

TEST(PlyReader, MalformedHeaders) {
    const std::string dir = tests::TempDir();
    WriteText(dir + "/n.ply", "PLY is not here\n");
    ExpectReadError(dir + "/n.ply", {"not a PLY file"});
    WriteText(dir + "/e.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n");
    ExpectReadError(dir + "/e.ply", {"end_header"});
    WriteText(dir + "/f.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n");
    ExpectReadError(dir + "/f.ply", {"unknown format"});
    WriteText(dir + "/v.ply", "ply\nformat ascii 1.0\nelement face 0\nend_header\n");
    ExpectReadError(dir + "/v.ply", {"no 'vertex' element"});
    WriteText(dir + "/a.ply",
              "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
              "property float y\nproperty float z\nend_header\n1 two 3\n");
    ExpectReadError(dir + "/a.ply", {"vertex 0 property 'y'", "'two'"});
}

TEST(PlyReader, UnknownExtensionEmptyAndMissingFile) {
    const std::string dir = tests::TempDir();
    WriteText(dir + "/x.obj", "v 1 2 3\n");
    ExpectReadError(dir + "/x.obj", {"unknown extension '.obj'"});
    WriteText(dir + "/empty.ply", "");
    ExpectReadError(dir + "/empty.ply", {"is empty"});
    WriteText(dir + "/empty.splat", "");
    ExpectReadError(dir + "/empty.splat", {"is empty"});
    ExpectReadError(dir + "/absent.ply", {"Cannot open"});
}

TEST(PlyReader, NonFiniteValuesRefusedOrDropped) {
    const std::string path = tests::TempDir() + "/nan.ply";
    const auto names = GaussianPropertyNames(1);
    auto rows = PlausibleRows(1, 6);
    const size_t w = names.size();
    rows[2 * w + 1] = std::numeric_limits<float>::quiet_NaN();     // y of splat 2
    rows[4 * w + w - 6] = std::numeric_limits<float>::infinity();  // scale_1 of splat 4
    rows[5 * w + 12] = -std::numeric_limits<float>::infinity();    // an f_rest of splat 5
    WriteFloatPly(path, names, rows);
    ExpectReadError(path, {"splat 2", "non-finite", "position[1]"});

    int warnings = 0;
    auto previous = core::SetLogSink([&](core::LogLevel level, std::string_view msg) {
        if (level == core::LogLevel::Warning && msg.find("dropped 3 of 6") != msg.npos) ++warnings;
    });
    PointCloud cloud;
    ReadPointCloudOptions options;
    options.drop_non_finite = true;
    const auto report = ReadPointCloud(path, cloud, options);
    core::SetLogSink(previous);
    EXPECT_EQ(warnings, 1);
    EXPECT_EQ(report.dropped_non_finite, 3);
    ASSERT_EQ(cloud.NumPoints(), 3);
    const float* p = cloud.GetPointPositions().Data<float>();
    EXPECT_EQ(p[0], 0.0f);  // splats 0, 1, 3 survive, in order
    EXPECT_EQ(p[3], 1.0f);
    EXPECT_EQ(p[6], 3.0f);
}

TEST(PlyReader, AsciiNumbersPastDoubleRangeAreInfiniteOrZero) {
    // 1e999 overflows double: it must read as infinity and be refused like 1e300 in a float
    // property, not become 0; 1e-999 underflows to 0, the nearest double.
    const std::string dir = tests::TempDir();
    const std::string header =
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n";
    for (const std::string big : {"1e999", "-1e999", "1e300"}) {
        SCOPED_TRACE(big);
        WriteText(dir + "/big.ply", header + "1e-999 0 0\n" + big + " 0 0\n");
        ExpectReadError(dir + "/big.ply", {"splat 1", "non-finite", "position[0]"});
    }
    WriteText(dir + "/tiny.ply", header + "1e-999 -1e-999 2\n0.5 0 0\n");
    PointCloud cloud;
    ReadPointCloud(dir + "/tiny.ply", cloud);
    ASSERT_EQ(cloud.NumPoints(), 2);
    const float* p = cloud.GetPointPositions().Data<float>();
    EXPECT_EQ(p[0], 0.0f);
    EXPECT_EQ(p[1], 0.0f);
    EXPECT_EQ(p[2], 2.0f);
}

TEST(PlyReader, LogScaleOverflowCountsAsNonFinite) {
    const std::string path = tests::TempDir() + "/big.ply";
    const auto names = GaussianPropertyNames(0);
    auto rows = PlausibleRows(0, 2);
    rows[names.size() + 10] = 200.0f;  // scale_0 of splat 1: exp(200) overflows float
    WriteFloatPly(path, names, rows);
    ExpectReadError(path, {"splat 1", "scale (exp of log-scale)[0] = inf"});
}

TEST(PlyReader, ZeroQuaternionIsAnError) {
    const std::string path = tests::TempDir() + "/q.ply";
    const auto names = GaussianPropertyNames(0);
    auto rows = PlausibleRows(0, 3);
    rows[names.size() + 13] = 0.0f;  // rot_0 of splat 1 (others are already 0)
    WriteFloatPly(path, names, rows);
    ExpectReadError(path, {"splat 1", "zero rotation quaternion"});
}

TEST(PlyReader, QuaternionsAreNormalised) {
    const std::string path = tests::TempDir() + "/qn.ply";
    const auto names = GaussianPropertyNames(0);
    auto rows = PlausibleRows(0, 1);
    rows[13] = 3.0f;
    rows[14] = 4.0f;  // (3, 4, 0, 0) -> (0.6, 0.8, 0, 0)
    WriteFloatPly(path, names, rows);
    PointCloud cloud;
    ReadPointCloud(path, cloud);
    const float* q = cloud.GetPointAttr("rot").Data<float>();
    EXPECT_EQ(q[0], 0.6f);
    EXPECT_EQ(q[1], 0.8f);
}

TEST(PlyReader, TrailingBytesLoadWithWarning) {
    const std::string path = tests::TempDir() + "/tr.ply";
    WriteFloatPly(path, GaussianPropertyNames(0), PlausibleRows(0, 2), -1, "garbage!!");
    int warnings = 0;
    auto previous = core::SetLogSink([&](core::LogLevel level, std::string_view msg) {
        if (level == core::LogLevel::Warning && msg.find("ignoring 9 bytes") != msg.npos)
            ++warnings;
    });
    PointCloud cloud;
    const auto report = ReadPointCloud(path, cloud);
    core::SetLogSink(previous);
    EXPECT_EQ(report.trailing_bytes, 9);
    EXPECT_EQ(warnings, 1);
    EXPECT_EQ(cloud.NumPoints(), 2);
}

TEST(PlyReader, SecondVertexElementIsRefused) {
    // The reader took the last 'vertex' element: 0 splats, a black image, exit status 0.
    const std::string path = tests::TempDir() + "/two_vertex.ply";
    WriteText(path,
              "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
              "property float z\nelement vertex 0\nproperty float x\nproperty float y\n"
              "property float z\nend_header\n1 2 3\n");
    ExpectReadError(path, {path, "line 7", "element 'vertex' declared twice"});
}

TEST(PlyReader, HugeCountAfterTheVerticesDoesNotOverflow) {
    // 2^62 rows of 4 bytes after the vertices: the declared size overflowed int64 (UBSan;
    // the fuzz seed count_2pow62_after_vertex.ply is this file). The vertices read, and
    // nothing is reported as trailing: the declared rows would cover any file.
    const std::string path = tests::TempDir() + "/huge_after.ply";
    std::string bytes =
        "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
        "property float y\nproperty float z\nelement face 4611686018427387904\n"
        "property float w\nend_header\n";
    bytes += std::string(12 + 8, '\0');
    WriteText(path, bytes);
    PointCloud cloud;
    const auto report = ReadPointCloud(path, cloud);
    EXPECT_EQ(cloud.NumPoints(), 1);
    EXPECT_EQ(report.trailing_bytes, 0);
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
