// .ksplat reader: the shared mode-0 file against values computed independently, files the
// test assembles byte by byte in modes 0, 1 and 2 (buckets, partially filled buckets, SH in
// f32 / f16 / 8 bits, sections of different SH degree), and malformed files.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>

#include "IoTestHelpers.h"
#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using geometry::kSH_C0;
using geometry::PointCloud;

constexpr const char* kMinimal = "formats/minimal.ksplat";

const float* F(const PointCloud& cloud, const char* name) {
    return cloud.GetPointAttr(name).Data<float>();
}

// minimal.ksplat, from its bytes alone with this Python (struct and math only):
//   f32 = lambda v: struct.unpack('<f', struct.pack('<f', v))[0]
//   d = open('formats/minimal.ksplat', 'rb').read()
//   struct.unpack_from('<4B4I', d, 0)   # version 0.1, maxSections 1, -, -, splatCount 4
//   struct.unpack_from('<H', d, 20)     # compression mode 0
//   struct.unpack_from('<4IfHHIIIIH', d, 4096)  # 4 splats, max 4, bucket size 4, 1 bucket,
//                                                # block 10, storage 12, range 32767, ...
//   base = 4096 + 1024 + 12             # one section header, one 12-byte bucket
//   r = struct.unpack_from('<3f3f4f4B', d, base + 44 * i)
//   f_dc = [f32((b / 255 - 0.5) / SH_C0) for b in r[10:13]]
//   a = r[13] / 255; opacity = f32(math.log(a / (1 - a)))
// The rotation floats are (0, 0, 0, 1). SplatBuffer.js reads them as (w, x, y, z) (a
// half turn about z; the fixture's author probably meant identity in x, y, z, w order; the
// splats are isotropic, so both look the same); read-ksplat.ts reads them the same way.
TEST(Ksplat, SharedFileMatchesIndependentValues) {
    OPEN3D_REQUIRE_DATA(kMinimal);
    const std::string path = tests::DataPath(kMinimal);
    EXPECT_EQ(DetectPointCloudFileFormat(path), PointCloudFileFormat::kKsplat);
    PointCloud cloud;
    const ReadPointCloudReport report = ReadPointCloud(path, cloud);
    ASSERT_EQ(cloud.NumPoints(), 4);
    EXPECT_EQ(cloud.GaussianSplatGetSHOrder(), 0);
    EXPECT_EQ(report.trailing_bytes, 0);
    const float positions[4][3] = {{-1, 0, -1}, {0, 0, -1}, {-1, 0, 0}, {0, 0, 0}};
    const float dark = -0.590817928314209f, light = 0.590817928314209f;
    const float f_dc[4][3] = {{dark, dark, 0.006950799375772476f},
                              {light, dark, 0.006950799375772476f},
                              {dark, light, 0.006950799375772476f},
                              {light, light, 0.006950799375772476f}};
    for (int i = 0; i < 4; ++i) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(F(cloud, "positions")[i * 3 + c], positions[i][c]);
            EXPECT_EQ(F(cloud, "scale")[i * 3 + c], 0.1f);
            EXPECT_FLOAT_EQ(F(cloud, "f_dc")[i * 3 + c], f_dc[i][c]);
        }
        const float rot[4] = {0, 0, 0, 1};
        for (int c = 0; c < 4; ++c) EXPECT_EQ(F(cloud, "rot")[i * 4 + c], rot[c]);
        EXPECT_FLOAT_EQ(F(cloud, "opacity")[i], 2.219203472137451f);
    }
}

// ---------------------------------------------------------------------------------------
// A .ksplat writer of the test's own, from the layout described in KsplatFormat.cpp (which
// follows GaussianSplats3D's SplatBuffer.js generateFromUncompressedSplatArrays).

struct Splat {
    float position[3], scale[3], rot[4];  // rot (w, x, y, z)
    uint8_t rgba[4];
    std::vector<float> sh;  // degree-1 then degree-2 coefficients: sh[k * 3 + channel]
};

struct Bucket {
    float centre[3];
    std::vector<Splat> splats;
};

struct Section {
    int degree = 0;
    float block_size = 5.0f;
    uint32_t bucket_size = 0;  // the first `full` buckets hold exactly this many splats
    uint32_t full = 0;
    std::vector<Bucket> buckets;
};

uint16_t ToHalf(float f) {  // round to nearest even; the test's values are normal halves
    uint32_t x;
    std::memcpy(&x, &f, 4);
    const uint32_t sign = (x >> 16) & 0x8000;
    const int exponent = int((x >> 23) & 0xff) - 127 + 15;
    const uint32_t mantissa = x & 0x7fffff;
    if ((x & 0x7fffffff) == 0) return static_cast<uint16_t>(sign);
    EXPECT_TRUE(exponent > 0 && exponent < 31) << f;
    uint32_t h = (uint32_t(exponent) << 10) | (mantissa >> 13);
    const uint32_t rest = mantissa & 0x1fff;
    if (rest > 0x1000 || (rest == 0x1000 && (h & 1))) ++h;
    return static_cast<uint16_t>(sign | h);
}

struct Bytes {
    std::string data;
    template <typename T>
    void Put(T value) {
        data.append(reinterpret_cast<const char*>(&value), sizeof(T));
    }
    template <typename T>
    void PutAt(size_t offset, T value) {
        std::memcpy(&data[offset], &value, sizeof(T));
    }
};

constexpr uint32_t kRange = 32767;  // modes 1-2
constexpr float kSHMin = -2.0f, kSHMax = 3.0f;

uint16_t EncodeOffset(float position, float centre, float block_size) {
    const double v = std::round((double(position) - centre) * kRange / (block_size / 2.0)) + kRange;
    return static_cast<uint16_t>(std::clamp(v, 0.0, 2.0 * kRange + 1));
}

uint8_t EncodeSH8(float v) {  // SplatBuffer.js toUint8
    const double c = std::clamp(double(v), double(kSHMin), double(kSHMax));
    return static_cast<uint8_t>(
        std::clamp(std::floor((c - kSHMin) / (kSHMax - kSHMin) * 255), 0.0, 255.0));
}

std::string BuildKsplat(int mode, const std::vector<Section>& sections) {
    Bytes out;
    uint32_t total = 0;
    for (const auto& s : sections) {
        for (const auto& b : s.buckets) total += static_cast<uint32_t>(b.splats.size());
    }
    out.data.assign(4096, '\0');
    out.data[0] = 0;
    out.data[1] = 1;
    out.PutAt<uint32_t>(4, static_cast<uint32_t>(sections.size()));
    out.PutAt<uint32_t>(8, static_cast<uint32_t>(sections.size()));
    out.PutAt<uint32_t>(12, total);
    out.PutAt<uint32_t>(16, total);
    out.PutAt<uint16_t>(20, static_cast<uint16_t>(mode));
    out.PutAt<float>(36, kSHMin);
    out.PutAt<float>(40, kSHMax);
    std::string bodies;
    for (const Section& s : sections) {
        uint32_t count = 0;
        for (const auto& b : s.buckets) count += static_cast<uint32_t>(b.splats.size());
        const uint32_t partial = static_cast<uint32_t>(s.buckets.size()) - s.full;
        Bytes body;
        for (uint32_t b = s.full; b < s.buckets.size(); ++b) {
            body.Put<uint32_t>(static_cast<uint32_t>(s.buckets[b].splats.size()));
        }
        for (const Bucket& b : s.buckets) {
            for (float c : b.centre) body.Put<float>(c);
        }
        const int num_sh = s.degree == 0 ? 0 : s.degree == 1 ? 9 : 24;
        for (const Bucket& b : s.buckets) {
            for (const Splat& p : b.splats) {
                for (int c = 0; c < 3; ++c) {
                    if (mode == 0) {
                        body.Put<float>(p.position[c]);
                    } else {
                        body.Put<uint16_t>(EncodeOffset(p.position[c], b.centre[c], s.block_size));
                    }
                }
                for (float v : p.scale)
                    mode == 0 ? body.Put<float>(v) : body.Put<uint16_t>(ToHalf(v));
                for (float v : p.rot)
                    mode == 0 ? body.Put<float>(v) : body.Put<uint16_t>(ToHalf(v));
                for (uint8_t v : p.rgba) body.Put<uint8_t>(v);
                // Band 1 as R c1..c3, G c1..c3, B c1..c3, then band 2 as R c4..c8, G .., B ..
                std::vector<float> ordered;
                for (int ch = 0; ch < 3 && num_sh > 0; ++ch) {
                    for (int k = 0; k < 3; ++k) ordered.push_back(p.sh[k * 3 + ch]);
                }
                for (int ch = 0; ch < 3 && num_sh > 9; ++ch) {
                    for (int k = 3; k < 8; ++k) ordered.push_back(p.sh[k * 3 + ch]);
                }
                for (float v : ordered) {
                    if (mode == 0) body.Put<float>(v);
                    if (mode == 1) body.Put<uint16_t>(ToHalf(v));
                    if (mode == 2) body.Put<uint8_t>(EncodeSH8(v));
                }
            }
        }
        Bytes header;
        header.data.assign(1024, '\0');
        header.PutAt<uint32_t>(0, count);
        header.PutAt<uint32_t>(4, count);
        header.PutAt<uint32_t>(8, s.bucket_size);
        header.PutAt<uint32_t>(12, static_cast<uint32_t>(s.buckets.size()));
        header.PutAt<float>(16, s.block_size);
        header.PutAt<uint16_t>(20, 12);
        header.PutAt<uint32_t>(24, mode == 0 ? 0 : kRange);
        header.PutAt<uint32_t>(28, static_cast<uint32_t>(body.data.size()));
        header.PutAt<uint32_t>(32, s.full);
        header.PutAt<uint32_t>(36, partial);
        header.PutAt<uint16_t>(40, static_cast<uint16_t>(s.degree));
        out.data += header.data;
        bodies += body.data;
    }
    return out.data + bodies;
}

void WriteBytes(const std::string& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary) << bytes;
}

// A few distinct splats around a bucket centre, with SH of the given degree.
Splat MakeSplat(int i, const float centre[3], int degree) {
    Splat s;
    for (int c = 0; c < 3; ++c) {
        s.position[c] = centre[c] + 0.37f * float((i * 7 + c * 3) % 11 - 5) / 5.0f;
        s.scale[c] = 0.125f * float(1 + (i + c) % 4);  // exact in half precision
    }
    const float q[4] = {0.5f, -0.5f, 0.5f, 0.5f};
    for (int c = 0; c < 4; ++c) s.rot[c] = q[(c + i) % 4];
    for (int c = 0; c < 4; ++c) s.rgba[c] = static_cast<uint8_t>((i * 37 + c * 61 + 5) % 256);
    const int nc = geometry::NumSHRestCoeffs(degree);
    for (int k = 0; k < nc * 3; ++k) s.sh.push_back(0.01f * float((i * 13 + k * 7) % 200 - 100));
    return s;
}

// The cloud the reader should return for `sections`, splat for splat, and the position
// quantum of each (0 in mode 0).
std::vector<const Splat*> Flatten(const std::vector<Section>& sections) {
    std::vector<const Splat*> all;
    for (const auto& s : sections) {
        for (const auto& b : s.buckets) {
            for (const auto& p : b.splats) all.push_back(&p);
        }
    }
    return all;
}

void ExpectDecoded(int mode, const std::vector<Section>& sections, const PointCloud& cloud) {
    const std::vector<const Splat*> splats = Flatten(sections);
    ASSERT_EQ(cloud.NumPoints(), int64_t(splats.size()));
    int max_degree = 0;
    for (const auto& s : sections) max_degree = std::max(max_degree, s.degree);
    ASSERT_EQ(cloud.GaussianSplatGetSHOrder(), max_degree);
    const int nc = geometry::NumSHRestCoeffs(max_degree);
    int64_t i = 0;
    for (const Section& s : sections) {
        const int sec_nc = geometry::NumSHRestCoeffs(s.degree);
        // Half a position step: (block / 2 / range) / 2, plus float rounding.
        const double position_bound = mode == 0 ? 0.0 : s.block_size / 2.0 / kRange / 2 + 1e-6;
        for (const Bucket& b : s.buckets) {
            for (const Splat& p : b.splats) {
                SCOPED_TRACE("splat " + std::to_string(i));
                for (int c = 0; c < 3; ++c) {
                    EXPECT_NEAR(F(cloud, "positions")[i * 3 + c], p.position[c], position_bound);
                    EXPECT_EQ(F(cloud, "scale")[i * 3 + c], p.scale[c]);  // exact in f16
                    EXPECT_FLOAT_EQ(F(cloud, "f_dc")[i * 3 + c],
                                    float((p.rgba[c] / 255.0 - 0.5) / kSH_C0));
                }
                if (mode > 0) {  // the exact value: (u - range) * block / 2 / range + centre
                    const uint16_t u = EncodeOffset(p.position[0], b.centre[0], s.block_size);
                    EXPECT_FLOAT_EQ(
                        F(cloud, "positions")[i * 3],
                        float((u - double(kRange)) * (s.block_size / 2.0 / kRange) + b.centre[0]));
                }
                for (int c = 0; c < 4; ++c) EXPECT_EQ(F(cloud, "rot")[i * 4 + c], p.rot[c]);
                const double alpha = std::clamp(p.rgba[3] / 255.0, 1e-6, 1 - 1e-6);
                EXPECT_FLOAT_EQ(F(cloud, "opacity")[i], float(std::log(alpha / (1 - alpha))));
                for (int k = 0; k < nc; ++k) {
                    for (int ch = 0; ch < 3; ++ch) {
                        const float got = F(cloud, "f_rest")[(i * nc + k) * 3 + ch];
                        if (k >= sec_nc) {
                            EXPECT_EQ(got, 0.0f) << "coefficient " << k << " beyond the section's";
                            continue;
                        }
                        const float want = p.sh[k * 3 + ch];
                        if (mode == 0) {
                            EXPECT_EQ(got, want);
                        } else if (mode == 1) {
                            EXPECT_NEAR(got, want, std::abs(want) * 0x1p-11);
                        }
                        if (mode == 2) {  // floor to a 1/255 step of the range, so one step
                            EXPECT_EQ(got,
                                      float(EncodeSH8(want) / 255.0 * (kSHMax - kSHMin) + kSHMin));
                            EXPECT_LE(want - got, (kSHMax - kSHMin) / 255.0 + 1e-6);
                            EXPECT_GE(want - got, -1e-6);
                        }
                    }
                }
                ++i;
            }
        }
    }
}

// Section 0: two full buckets of 3 and two partially filled ones (2 and 1 splats);
// section 1: one partially filled bucket, another SH degree.
std::vector<Section> TwoSections(int degree0, int degree1) {
    std::vector<Section> sections(2);
    const float centres[4][3] = {{0, 0, 0}, {5, 0, 0}, {0, -5, 2.5f}, {-10, 7.5f, 5}};
    sections[0].degree = degree0;
    sections[0].bucket_size = 3;
    sections[0].full = 2;
    int id = 0;
    for (int b = 0; b < 4; ++b) {
        Bucket bucket;
        std::copy(centres[b], centres[b] + 3, bucket.centre);
        const int count = b < 2 ? 3 : b == 2 ? 2 : 1;
        for (int k = 0; k < count; ++k)
            bucket.splats.push_back(MakeSplat(id++, bucket.centre, degree0));
        sections[0].buckets.push_back(bucket);
    }
    sections[1].degree = degree1;
    sections[1].block_size = 2.0f;
    sections[1].bucket_size = 256;
    Bucket bucket{{100, 200, -300}, {}};
    for (int k = 0; k < 2; ++k) bucket.splats.push_back(MakeSplat(id++, bucket.centre, degree1));
    sections[1].buckets.push_back(bucket);
    return sections;
}

TEST(Ksplat, HandBuiltModes) {
    const std::string dir = tests::TempDir();
    for (int mode = 0; mode <= 2; ++mode) {
        for (auto [d0, d1] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{2, 1}, std::pair{0, 2}}) {
            SCOPED_TRACE("mode " + std::to_string(mode) + ", SH degrees " + std::to_string(d0) +
                         " and " + std::to_string(d1));
            const std::vector<Section> sections = TwoSections(d0, d1);
            const std::string path = dir + "/hand.ksplat";
            WriteBytes(path, BuildKsplat(mode, sections));
            PointCloud cloud;
            const ReadPointCloudReport report = ReadPointCloud(path, cloud);
            EXPECT_EQ(report.trailing_bytes, 0);
            ExpectDecoded(mode, sections, cloud);
        }
    }
}

TEST(Ksplat, DefaultSHRangeAndTrailingBytes) {
    // Mode 2 with the header's SH range left 0: GaussianSplats3D uses -1.5 .. 1.5.
    const std::vector<Section> sections = TwoSections(1, 1);
    std::string bytes = BuildKsplat(2, sections);
    std::memset(&bytes[36], 0, 8);
    bytes += "tail";
    const std::string path = tests::TempDir() + "/default_range.ksplat";
    WriteBytes(path, bytes);
    PointCloud cloud;
    const ReadPointCloudReport report = ReadPointCloud(path, cloud);
    EXPECT_EQ(report.trailing_bytes, 4);
    const Splat& first = *Flatten(sections)[0];
    // sh[0] (coefficient 1, red) was stored as byte EncodeSH8(sh[0]) over -2 .. 3.
    const double expected = EncodeSH8(first.sh[0]) / 255.0 * 3.0 - 1.5;
    EXPECT_FLOAT_EQ(F(cloud, "f_rest")[0], float(expected));
}

TEST(Ksplat, MalformedFilesGiveCleanErrors) {
    const std::string path = tests::TempDir() + "/bad.ksplat";
    const std::string good = BuildKsplat(1, TwoSections(2, 1));
    auto with = [&](auto edit) {
        std::string bytes = good;
        edit(bytes);
        WriteBytes(path, bytes);
    };
    auto put32 = [](std::string& b, size_t at, uint32_t v) { std::memcpy(&b[at], &v, 4); };
    with([](std::string& b) { b.resize(1000); });
    ExpectReadError(path, {"4096-byte header"});
    with([](std::string& b) { b.resize(b.size() - 5); });
    ExpectReadError(path, {"section 1", "only"});
    with([](std::string& b) { b[0] = 1; });
    ExpectReadError(path, {"version 1.1"});
    with([](std::string& b) { b[20] = 3; });
    ExpectReadError(path, {"compression mode 3"});
    with([&](std::string& b) { put32(b, 4, 1000000); });
    ExpectReadError(path, {"1000000 sections"});
    with([&](std::string& b) { put32(b, 16, 99); });
    ExpectReadError(path, {"splatCount 99", "sections hold 11"});
    with([&](std::string& b) { b[4096 + 40] = 3; });
    ExpectReadError(path, {"section 0", "SH degree 3"});
    with([&](std::string& b) { put32(b, 4096, 10); });  // splatCount > maxSplatCount
    ExpectReadError(path, {"section 0", "exceeds maxSplatCount"});
    with([&](std::string& b) { put32(b, 4096 + 36, 7); });  // more partial buckets than buckets
    ExpectReadError(path, {"section 0"});
    // The last partially filled bucket claims 0 splats: splat 8 is in no bucket.
    with([&](std::string& b) { put32(b, 4096 + 2 * 1024 + 4, 0); });
    ExpectReadError(path, {"section 0", "splat 8 lies beyond"});
    with([&](std::string& b) { b[4096 + 20] = 4; });  // bucket storage too small for a centre
    ExpectReadError(path, {"section 0", "bucket centre"});
}

TEST(Ksplat, KsplatNamedSplatIsNamed) {
    // Before, a .ksplat renamed to .splat read as "truncated .splat" (or, at a size that is a
    // multiple of 32, as garbage splats).
    const std::string good = BuildKsplat(1, TwoSections(2, 1));
    const std::string path = tests::TempDir() + "/renamed.splat";
    WriteBytes(path, good);
    ExpectReadError(path, {"renamed.splat", "is a .ksplat file", "rename it to .ksplat"});
    std::string padded = good;
    padded.resize((padded.size() + 31) / 32 * 32, '\0');
    WriteBytes(path, padded);
    ExpectReadError(path, {"is a .ksplat file"});
}

// Regenerates the .ksplat fuzz seed (run with --gtest_also_run_disabled_tests).
TEST(Ksplat, DISABLED_WriteFuzzSeed) {
    WriteBytes(std::string(OPEN3D_TEST_SOURCE_DIR) + "/fuzz/seeds/mode1_sh2.ksplat",
               BuildKsplat(1, TwoSections(2, 1)));
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
