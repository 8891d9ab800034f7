// SPZ files assembled byte by byte (SpzTestFiles.h): flags, extensions and degree four, the
// fuzz seeds, malformed files, and what the writer refuses.
#include "SpzTestFiles.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using namespace spz_test;

TEST(SpzFormat, FlagsExtensionsAndDegreeFour) {
    const std::string dir = tests::TempDir();
    PointCloud minimal;
    ReadPointCloud(tests::DataPath("formats/minimal-v4.spz"), minimal);
    RawSpz r;
    r.n = 1;
    PutFixed(r.streams[0], {4096, 8192, 12288});
    r.streams[1] = {200};
    r.streams[2] = {1, 2, 3};
    r.streams[3] = {4, 5, 6};
    tests::AppendU32(r.streams[4], 3u << 30);
    // Antialiased: read, and said in a warning.
    r.flags = 0x1;
    WriteBytes(dir + "/aa.spz", V4Bytes(r));
    PointCloud c;
    auto w = tests::CaptureWarnings([&] { ReadPointCloud(dir + "/aa.spz", c); });
    ASSERT_EQ(w.size(), 1u);
    EXPECT_NE(w[0].find("antialiased"), std::string::npos);
    // Extensions: an unknown record is skipped with a warning; SPZ_ADOBE_coordinate_system
    // RDF (6) means no axis change.
    r.flags = 0x2;
    tests::AppendU32(r.extensions, 0x12340001);
    tests::AppendU32(r.extensions, 3);
    r.extensions.insert(r.extensions.end(), {9, 9, 9});
    tests::AppendU32(r.extensions, 0xADBE0003);
    tests::AppendU32(r.extensions, 4);
    tests::AppendU32(r.extensions, 6);
    WriteBytes(dir + "/ext.spz", V4Bytes(r));
    w = tests::CaptureWarnings([&] { ReadPointCloud(dir + "/ext.spz", c); });
    ASSERT_EQ(w.size(), 1u);
    EXPECT_NE(w[0].find("0x12340001"), std::string::npos);
    EXPECT_EQ(F(c, "positions")[1], 2.0f);
    EXPECT_EQ(F(c, "positions")[2], 3.0f);
    r.extensions.resize(r.extensions.size() - 4);
    tests::AppendU32(r.extensions, 10);  // RFD: the rotated family
    WriteBytes(dir + "/rfd.spz", V4Bytes(r));
    ExpectReadError(dir + "/rfd.spz", {"SPZ_ADOBE_coordinate_system", "10"});
    // Same in a gzip stream, records after the arrays.
    r.extensions.resize(r.extensions.size() - 4);
    tests::AppendU32(r.extensions, 4);  // RUB, the default
    r.version = 3;
    WriteBytes(dir + "/ext3.spz", LegacyBytes(r));
    ReadPointCloud(dir + "/ext3.spz", c);
    EXPECT_EQ(F(c, "positions")[2], -3.0f);
    // Degree 4: band 4 (27 of 72 values) is dropped with a warning.
    r.flags = 0;
    r.extensions.clear();
    r.degree = 4;
    for (int k = 0; k < 72; ++k) r.streams[5].push_back(uint8_t(k));
    WriteBytes(dir + "/deg4.spz", LegacyBytes(r));
    w = tests::CaptureWarnings([&] { ReadPointCloud(dir + "/deg4.spz", c); });
    ASSERT_EQ(w.size(), 1u);
    EXPECT_NE(w[0].find("band 4"), std::string::npos);
    EXPECT_EQ(c.GaussianSplatGetSHOrder(), 3);
    EXPECT_EQ(F(c, "f_rest")[44], float((44 - 128) / 128.0));  // k = 14: sign +1
}

TEST(SpzFormat, FuzzSeedsAreValid) {
    // tests/fuzz/seeds/*.spz start fuzz_spz_reader from every layout the reader knows.
    int count = 0;
    for (const auto& entry :
         std::filesystem::directory_iterator(std::string(OPEN3D_TEST_SOURCE_DIR) + "/fuzz/seeds")) {
        if (entry.path().extension() != ".spz") continue;
        PointCloud cloud;
        tests::CaptureWarnings([&] { ReadPointCloud(entry.path().string(), cloud); });
        EXPECT_GT(cloud.NumPoints(), 0) << entry.path();
        ++count;
    }
    EXPECT_GE(count, 7);
}

// ---- malformed files: a clean error naming the file and the field ----

TEST(SpzFormat, MalformedFiles) {
    const std::string dir = tests::TempDir();
    const Bytes good = ReadBytes(tests::DataPath("formats/minimal-v4.spz"));
    const auto write = [&](const std::string& name, Bytes b) {
        WriteBytes(dir + "/" + name, b);
        return dir + "/" + name;
    };
    const auto patch32 = [&](Bytes b, size_t at, uint32_t v) {
        for (int i = 0; i < 4; ++i) b[at + i] = uint8_t(v >> (8 * i));
        return b;
    };
    ExpectReadError(write("short.spz", Bytes(good.begin(), good.begin() + 20)),
                    {"truncated SPZ header", "20 bytes"});
    ExpectReadError(write("magic.spz", patch32(good, 0, 0x5153474e)), {"'magic'"});
    ExpectReadError(write("version.spz", patch32(good, 4, 5)), {"'version' is 5"});
    ExpectReadError(write("v3plain.spz", patch32(good, 4, 3)), {"'version' is 3", "gzip"});
    Bytes degree = good;
    degree[12] = 5;
    ExpectReadError(write("degree.spz", degree), {"'shDegree' is 5"});
    Bytes fractional = good;
    fractional[13] = 40;  // every position would round to the origin
    ExpectReadError(write("fractional.spz", fractional), {"'fractionalBits' is 40", "0..30"});
    Bytes streams = good;
    streams[15] = 6;
    ExpectReadError(write("streams.spz", streams), {"'numStreams' is 6"});
    ExpectReadError(write("toc.spz", patch32(good, 16, 200)), {"'tocByteOffset' is 200"});
    // Stream 4 (rotations) claims more compressed bytes than the file has.
    ExpectReadError(write("past.spz", patch32(good, 32 + 4 * 16, 1000)),
                    {"stream 4 (rotations)", "compressedSize 1000", "passes the end"});
    // numPoints 1000 with streams for 4 splats.
    ExpectReadError(write("count.spz", patch32(good, 8, 1000)),
                    {"stream 0 (positions)", "uncompressedSize is 36", "numPoints 1000"});
    // numPoints 2^31 - 1 with a TOC to match: refused before allocating 19 GB.
    Bytes huge = patch32(good, 8, 0x7fffffff);
    for (int s = 0; s < 5; ++s) {
        const uint64_t per_splat[5] = {9, 1, 3, 3, 4};
        const uint64_t size = 0x7fffffffull * per_splat[s];
        for (int i = 0; i < 8; ++i) huge[32 + s * 16 + 8 + i] = uint8_t(size >> (8 * i));
    }
    ExpectReadError(write("huge.spz", huge), {"stream 0 (positions)", "cannot hold"});
    // The alphas stream decompresses to 5 bytes while the TOC and numPoints say 4.
    RawSpz r;
    r.n = 4;
    r.streams[0].resize(36);
    r.streams[1] = {1, 2, 3, 4, 5};
    r.streams[2].resize(12);
    r.streams[3].resize(12);
    r.streams[4].resize(16);
    Bytes wrong = V4Bytes(r);
    wrong[32 + 16 + 8] = 4;  // TOC uncompressedSize of stream 1
    ExpectReadError(write("size.spz", wrong), {"stream 1 (alphas)", "holds 5 bytes"});
    // Trailing bytes are reported, not fatal.
    Bytes trailing = good;
    trailing.insert(trailing.end(), {1, 2, 3});
    PointCloud cloud;
    ReadPointCloudReport report;
    tests::CaptureWarnings(
        [&] { report = ReadPointCloud(write("trailing.spz", trailing), cloud); });
    EXPECT_EQ(report.trailing_bytes, 3);

    // Legacy (gzip) layout.
    r = RawSpz();
    r.version = 3;
    r.n = 2;
    r.streams[0].resize(18);
    r.streams[1].resize(2);
    r.streams[2].resize(6);
    r.streams[3].resize(6);
    r.streams[4].resize(8, 0xc0);
    Bytes legacy = LegacyBytes(r, false);
    ExpectReadError(write("gz_short.spz", GzipBytes(legacy.data(), 10)),
                    {"truncated SPZ header", "10 bytes"});
    Bytes cut = GzipBytes(legacy.data(), legacy.size());
    cut.resize(cut.size() - 12);
    ExpectReadError(write("gz_cut.spz", cut), {"gzip stream", "truncated"});
    ExpectReadError(write("gz_count.spz", LegacyBytes([&] {
                              RawSpz big = r;
                              big.n = 3;
                              return big;
                          }())),
                    {"'numPoints' is 3", "needs 60 bytes", "holds 40"});
    ExpectReadError(write("gz_v4.spz",
                          [&] {
                              Bytes b = patch32(legacy, 4, 4);
                              return GzipBytes(b.data(), b.size());
                          }()),
                    {"'version' is 4"});
    ExpectReadError(write("gz_magic.spz",
                          [&] {
                              Bytes b = patch32(legacy, 0, 0);
                              return GzipBytes(b.data(), b.size());
                          }()),
                    {"'magic'"});
}

TEST(SpzFormat, WriterRefusesWhatSpzCannotHold) {
    const std::string dir = tests::TempDir();
    PointCloud cloud;
    ReadPointCloud(tests::DataPath("formats/minimal-v4.spz"), cloud);
    cloud.GetPointAttr("opacity").Data<float>()[2] = NAN;
    try {
        WritePointCloud(dir + "/nan.spz", cloud);
        ADD_FAILURE() << "no error";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("splat 2 has a non-finite opacity"), std::string::npos)
            << e.what();
    }
    ReadPointCloud(tests::DataPath("formats/minimal-v4.spz"), cloud);
    cloud.GetPointAttr("scale").Data<float>()[3] = -1.0f;
    EXPECT_THROW(WritePointCloud(dir + "/neg.spz", cloud), core::Open3DError);
    EXPECT_THROW(
        WritePointCloud(dir + "/plain.spz", PointCloud(Tensor({2, 3}, core::Dtype::Float32))),
        core::Open3DError);
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
