// SPZ reader and writer (cpp/open3d/t/io/SpzFormat.cpp): the shared minimal files and
// biker.spz against values computed without our reader, files assembled byte by byte for
// v1 / v2 / v3 / SH signs, and round trips within SPZ's quantisation (extensions, malformed
// files and the writer's refusals: SpzFormatFilesTest.cpp).
//
// Expected values of minimal-v3.spz / minimal-v4.spz (the same 4 splats) come from this
// Python (standard library and the zstd command line; run in ../shared/data/formats):
//   import gzip, math, struct, subprocess
//   def streams(name):
//       d = open(name, 'rb').read()
//       if d[:2] == b'\x1f\x8b':  # v3: one gzip member, 4 splats after the 16-byte header
//           d, o, out = gzip.decompress(d), 16, []
//           for size in (36, 4, 12, 12, 16):
//               out.append(d[o:o + size])
//               o += size
//           return out
//       toc = struct.unpack_from('<I', d, 16)[0]
//       o, out = toc + 16 * d[15], []
//       for s in range(d[15]):
//           c, u = struct.unpack_from('<QQ', d, toc + 16 * s)
//           run = subprocess.run(['zstd', '-dc'], input=d[o:o + c], capture_output=True)
//           out.append(run.stdout)
//           o += c
//       return out
//   for name in ('minimal-v3.spz', 'minimal-v4.spz'):
//       P, A, C, S, R = streams(name)
//       for i in range(4):
//           p = [int.from_bytes(P[9 * i + 3 * k:][:3], 'little', signed=True) / 4096
//                for k in range(3)]
//           print(i, (p[0], -p[1], -p[2]), math.log(A[i] / 255 / (1 - A[i] / 255)),
//                 [(C[3 * i + k] / 255 - 0.5) / 0.15 for k in range(3)],
//                 [math.exp(S[3 * i + k] / 16 - 10) for k in range(3)],
//                 hex(struct.unpack_from('<I', R, 4 * i)[0]))
// It prints, for splat i: position (RDF), opacity, f_dc, scale, packed rotation:
//   0 (-1, 0, -1) 2.2192034840549946 [-0.5882352941176472, -0.5882352941176472,
//     0.013071895424836555] [0.0990134083638263 x3] 0xc0000000
//   1 (0, 0, -1)  ... [0.5882352941176472, -0.5882352941176472, 0.013071895424836555]
//   2 (-1, 0, 0)  ... [-0.5882352941176472, 0.5882352941176472, 0.013071895424836555]
//   3 (0, 0, 0)   ... [0.5882352941176472, 0.5882352941176472, 0.013071895424836555]
// (same opacity and scale for every splat; 0xc0000000: largest component w, the other
// three 0, i.e. rotation (1, 0, 0, 0); the v3 and v4 files print the same).
#include "SpzTestFiles.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using namespace spz_test;

TEST(SpzFormat, MinimalFilesMatchIndependentDecode) {
    OPEN3D_REQUIRE_DATA("formats/minimal-v3.spz");
    const float positions[4][3] = {{-1, 0, -1}, {0, 0, -1}, {-1, 0, 0}, {0, 0, 0}};
    const int colours[4][3] = {{105, 105, 128}, {150, 105, 128}, {105, 150, 128}, {150, 150, 128}};
    const auto f_dc = [](int byte) {
        return byte == 105   ? -0.5882352941176472
               : byte == 150 ? 0.5882352941176472
                             : 0.013071895424836555;
    };
    PointCloud v3, v4;
    ReadPointCloud(tests::DataPath("formats/minimal-v3.spz"), v3);
    ReadPointCloud(tests::DataPath("formats/minimal-v4.spz"), v4);
    ASSERT_EQ(v3.NumPoints(), 4);
    EXPECT_EQ(v3.GaussianSplatGetSHOrder(), 0);
    for (int i = 0; i < 4; ++i) {
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(F(v3, "positions")[i * 3 + k], positions[i][k]);
            EXPECT_FLOAT_EQ(F(v3, "f_dc")[i * 3 + k], float(f_dc(colours[i][k])));
            EXPECT_FLOAT_EQ(F(v3, "scale")[i * 3 + k], float(0.0990134083638263));
        }
        EXPECT_FLOAT_EQ(F(v3, "opacity")[i], float(2.2192034840549946));
        for (int k = 0; k < 4; ++k) EXPECT_EQ(F(v3, "rot")[i * 4 + k], k == 0 ? 1.0f : 0.0f);
    }
    EXPECT_TRUE(v3 == v4);  // the same grid in both versions
}

// Bounds of SPZ's quantisation, each half a step of its 8-bit (or 9-bit) grid:
//   opacity: sigmoid in 1/255 steps -> 0.5/255 (+1e-6 margin at alpha 0 and 255)
//   f_dc: colour f_dc * 0.15 * 255 in unit steps -> 0.5 / 38.25 in f_dc
//   scale: log-scale in 1/16 steps -> 1/32 in log-scale
//   rotation: the three stored components in sqrt(1/2)/511 steps -> h = 6.92e-4 each; the
//     derived largest |dq_L| <= sum |q_i + q_i'| |dq_i| / (q_L + q_L') <~ 3h (|q_i| <= q_L),
//     so |dq| <= sqrt(3 h^2 + 9 h^2) = 2.40e-3 (the writer's choice among near-tied largest
//     components only ever lowers |dq|)
//   SH: c * 128 + 128 on a grid of 8 (degree 1) or 16 (degrees 2-3) -> 4/128 and 8/128,
//     inside [-1, 127/128]
constexpr double kOpacityBound = 0.5 / 255 + 1e-6;
constexpr double kFDcBound = 0.5 / (0.15 * 255) + 1e-6;
constexpr double kLogScaleBound = 1.0 / 32 + 1e-6;
constexpr double kRotationBound = 3.4641016 * 0.70710678 / 511 / 2 + 1e-6;  // sqrt(12) h

struct MaxErrors {
    double position = 0, opacity = 0, f_dc = 0, log_scale = 0, rotation = 0;
    double sh = 0;  // as a fraction of its bound
};

/// Compares a cloud read from SPZ with its source within the bounds above; positions within
/// `position_bound`. Returns the measured maxima.
MaxErrors ExpectWithinQuantisation(const PointCloud& spz, const PointCloud& source,
                                   double position_bound) {
    MaxErrors m;
    const int64_t n = source.NumPoints();
    EXPECT_EQ(spz.NumPoints(), n);
    const int degree = source.GaussianSplatGetSHOrder();
    EXPECT_EQ(spz.GaussianSplatGetSHOrder(), degree);
    const int nc = geometry::NumSHRestCoeffs(degree);
    for (int64_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) {
            const int64_t j = i * 3 + k;
            m.position = std::max(
                m.position, double(std::abs(F(spz, "positions")[j] - F(source, "positions")[j])));
            const double dc =
                std::clamp(double(F(source, "f_dc")[j]), -127.5 / 38.25, 127.5 / 38.25);
            m.f_dc = std::max(m.f_dc, std::abs(F(spz, "f_dc")[j] - dc));
            const double log_scale =
                std::clamp(std::log(double(F(source, "scale")[j])), -10.0, 255.0 / 16 - 10);
            m.log_scale =
                std::max(m.log_scale, std::abs(std::log(double(F(spz, "scale")[j])) - log_scale));
        }
        m.opacity = std::max(
            m.opacity, std::abs(Sigmoid(F(spz, "opacity")[i]) - Sigmoid(F(source, "opacity")[i])));
        const float* q0 = F(source, "rot") + i * 4;
        const float* q1 = F(spz, "rot") + i * 4;
        double norm = 0, dot = 0;
        for (int k = 0; k < 4; ++k) {
            norm += double(q0[k]) * q0[k];
            dot += double(q0[k]) * q1[k];
        }
        double distance = 0;  // |q1 - (+-q0 / |q0|)|
        for (int k = 0; k < 4; ++k) {
            const double d = q1[k] - q0[k] / std::sqrt(norm) * (dot < 0 ? -1 : 1);
            distance += d * d;
        }
        m.rotation = std::max(m.rotation, std::sqrt(distance));
        for (int k = 0; k < nc * 3; ++k) {
            const double v =
                std::clamp(double(F(source, "f_rest")[i * nc * 3 + k]), -1.0, 127.0 / 128);
            const double bound = (k < 9 ? 4.0 : 8.0) / 128 + 1e-6;
            const double e = std::abs(F(spz, "f_rest")[i * nc * 3 + k] - v);
            m.sh = std::max(m.sh, e / bound);
            if (e > bound) {
                ADD_FAILURE() << "splat " << i << " f_rest[" << k << "] " << e;
                return m;
            }
        }
    }
    EXPECT_LE(m.position, position_bound);
    EXPECT_LE(m.opacity, kOpacityBound);
    EXPECT_LE(m.f_dc, kFDcBound);
    EXPECT_LE(m.log_scale, kLogScaleBound);
    EXPECT_LE(m.rotation, kRotationBound);
    return m;
}

void Print(const char* what, const MaxErrors& m) {
    std::cout << "[spz] " << what << ": max |d position| " << m.position << ", |d sigmoid| "
              << m.opacity << ", |d f_dc| " << m.f_dc << ", |d log-scale| " << m.log_scale
              << ", |d q| " << m.rotation << ", |d SH| / bound " << m.sh << "\n";
}

TEST(SpzFormat, BikerMatchesItsPly) {
    OPEN3D_REQUIRE_DATA("formats/biker.spz");
    OPEN3D_REQUIRE_DATA("biker/biker_152k.ply");
    PointCloud spz, ply;
    ReadPointCloud(tests::DataPath("formats/biker.spz"), spz);
    ReadPointCloud(tests::DataPath("biker/biker_152k.ply"), ply);
    ASSERT_EQ(spz.NumPoints(), 152746);
    // formats/README.md: the 24-bit positions / 4096 equal the PLY's after the axis change.
    const MaxErrors m = ExpectWithinQuantisation(spz, ply, 0.0);
    Print("biker.spz vs biker_152k.ply", m);
}

TEST(SpzFormat, WriterReproducesBikerStreams) {
    // Reading biker.spz and writing it again gives the same attribute bytes the original
    // encoder wrote: the writer quantises like the reference (only zstd's output may differ).
    OPEN3D_REQUIRE_DATA("formats/biker.spz");
    const std::string path = tests::TempDir() + "/biker.spz";
    PointCloud cloud;
    ReadPointCloud(tests::DataPath("formats/biker.spz"), cloud);
    WritePointCloud(path, cloud);
    const Bytes original = ReadBytes(tests::DataPath("formats/biker.spz"));
    const Bytes written = ReadBytes(path);
    EXPECT_TRUE(std::equal(original.begin(), original.begin() + 32, written.begin()));
    const std::vector<Bytes> a = V4Streams(original), b = V4Streams(written);
    ASSERT_EQ(a.size(), 5u);
    ASSERT_EQ(b.size(), 5u);
    for (int s = 0; s < 5; ++s) EXPECT_TRUE(a[s] == b[s]) << "stream " << s;
}

// ---- round trips ----

void RoundTrip(const char* scene, int expected_degree) {
    OPEN3D_REQUIRE_DATA(scene);
    const std::string dir = tests::TempDir();
    PointCloud ply, once, twice;
    ReadPointCloud(tests::DataPath(scene), ply);
    ASSERT_EQ(ply.GaussianSplatGetSHOrder(), expected_degree);
    WritePointCloud(dir + "/a.spz", ply);
    ReadPointCloud(dir + "/a.spz", once);
    const Bytes a = ReadBytes(dir + "/a.spz");
    const int fractional_bits = a[13];
    Print(scene, ExpectWithinQuantisation(once, ply, std::ldexp(0.5, -fractional_bits)));
    // A cloud read from SPZ lies on SPZ's grid: writing it again gives the same file.
    WritePointCloud(dir + "/b.spz", once);
    EXPECT_TRUE(ReadBytes(dir + "/b.spz") == a);
    ReadPointCloud(dir + "/b.spz", twice);
    EXPECT_TRUE(twice == once);
}

TEST(SpzFormat, RoundTripBiker) { RoundTrip("biker/biker_152k.ply", 0); }
TEST(SpzFormat, RoundTripPcShortSH3) { RoundTrip("pc_short/pc_short.ply", 3); }

TEST(SpzFormat, RoundTripRandomCloudEveryDegree) {
    std::mt19937 rng(7);
    std::normal_distribution<float> normal(0.0f, 1.0f);
    for (int degree = 0; degree <= 3; ++degree) {
        const int64_t n = 500;
        const int nc = geometry::NumSHRestCoeffs(degree);
        Tensor positions({n, 3}, core::Dtype::Float32), scale({n, 3}, core::Dtype::Float32),
            rot({n, 4}, core::Dtype::Float32), opacity({n, 1}, core::Dtype::Float32),
            f_dc({n, 3}, core::Dtype::Float32), f_rest({n, nc, 3}, core::Dtype::Float32);
        for (int64_t i = 0; i < n * 3; ++i) {
            positions.Data<float>()[i] = 5 * normal(rng);
            scale.Data<float>()[i] = DecodeLogScale(-4 + normal(rng));
            f_dc.Data<float>()[i] = normal(rng);
        }
        for (int64_t i = 0; i < n * 4; ++i) rot.Data<float>()[i] = normal(rng);
        for (int64_t i = 0; i < n; ++i) opacity.Data<float>()[i] = 3 * normal(rng);
        for (int64_t i = 0; i < n * nc * 3; ++i) f_rest.Data<float>()[i] = 0.3f * normal(rng);
        PointCloud cloud(positions);
        cloud.SetPointAttr("scale", scale);
        cloud.SetPointAttr("rot", rot);
        cloud.SetPointAttr("opacity", opacity);
        cloud.SetPointAttr("f_dc", f_dc);
        if (degree > 0) cloud.SetPointAttr("f_rest", f_rest);
        const std::string dir = tests::TempDir();
        WritePointCloud(dir + "/a.spz", cloud);
        PointCloud back;
        ReadPointCloud(dir + "/a.spz", back);
        ExpectWithinQuantisation(back, cloud, std::ldexp(0.5, -12));
        WritePointCloud(dir + "/b.spz", back);
        EXPECT_TRUE(ReadBytes(dir + "/b.spz") == ReadBytes(dir + "/a.spz")) << degree;
    }
}

TEST(SpzFormat, FractionalBitsFollowTheExtent) {
    // 12 bits hold |p| <= (2^23 - 1) / 2^12 = 2047.99...; 3000 needs 11 (|p| <= 4095.99).
    const std::string dir = tests::TempDir();
    PointCloud cloud;
    ReadPointCloud(tests::DataPath("formats/minimal-v4.spz"), cloud);
    WritePointCloud(dir + "/a.spz", cloud);
    EXPECT_EQ(ReadBytes(dir + "/a.spz")[13], 12);
    cloud.GetPointAttr("positions").Data<float>()[4] = -3000.3f;
    WritePointCloud(dir + "/b.spz", cloud);
    EXPECT_EQ(ReadBytes(dir + "/b.spz")[13], 11);
    PointCloud back;
    ReadPointCloud(dir + "/b.spz", back);
    EXPECT_NEAR(F(back, "positions")[4], -3000.3f, std::ldexp(0.5, -11));
    cloud.GetPointAttr("positions").Data<float>()[4] = 9e6f;  // beyond 2^23 - 1 at 0 bits
    EXPECT_THROW(WritePointCloud(dir + "/c.spz", cloud), core::Open3DError);
}

// ---- layouts assembled by hand ----

TEST(SpzFormat, AxisChangeAndRotationEncodings) {
    const std::string dir = tests::TempDir();
    // One splat, stored RUB position (1, 2, 3) * 4096 and a smallest-three rotation with the
    // largest component y (index 1): x = -217, z = +72, w = +145 in sqrt(1/2)/511 units,
    // packed x highest: (1 << 30) | (1 << 9 | 217) << 20 | 72 << 10 | 145.
    RawSpz r;
    r.version = 3;
    r.n = 1;
    PutFixed(r.streams[0], {4096, 8192, 12288});
    r.streams[1] = {255};
    r.streams[2] = {0, 255, 128};
    r.streams[3] = {0, 160, 255};
    const uint32_t packed = 1u << 30 | (1u << 9 | 217) << 20 | 72u << 10 | 145;
    tests::AppendU32(r.streams[4], packed);
    WriteBytes(dir + "/v3.spz", LegacyBytes(r));
    PointCloud c;
    ReadPointCloud(dir + "/v3.spz", c);
    EXPECT_EQ(F(c, "positions")[0], 1.0f);
    EXPECT_EQ(F(c, "positions")[1], -2.0f);
    EXPECT_EQ(F(c, "positions")[2], -3.0f);
    EXPECT_FLOAT_EQ(F(c, "scale")[0], std::exp(-10.0f));
    EXPECT_FLOAT_EQ(F(c, "scale")[1], 1.0f);
    EXPECT_FLOAT_EQ(F(c, "scale")[2], std::exp(255 / 16.0f - 10));
    EXPECT_FLOAT_EQ(F(c, "f_dc")[0], float(-0.5 / 0.15));
    EXPECT_FLOAT_EQ(F(c, "f_dc")[1], float(0.5 / 0.15));
    EXPECT_NEAR(Sigmoid(F(c, "opacity")[0]), 1.0, 1e-6);  // alpha 255 stays finite
    const double s = std::sqrt(0.5) / 511;
    const double x = -217 * s, z = 72 * s, w = 145 * s, y = std::sqrt(1 - x * x - z * z - w * w);
    const double expected[4] = {w, x, -y, -z};  // RUB -> RDF: (w, x, -y, -z)
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(F(c, "rot")[k], expected[k], 1e-7) << k;

    // v2: rotation (x, y, z) bytes q * 127.5 + 127.5, w >= 0 derived. v1: float16 positions.
    for (uint32_t version : {1u, 2u}) {
        RawSpz v = r;
        v.version = version;
        v.streams[0].clear();
        if (version == 1) {
            for (uint16_t h : {0x3E00, 0xC000, 0x1400}) {  // 1.5, -2, 2^-10
                v.streams[0].push_back(uint8_t(h));
                v.streams[0].push_back(uint8_t(h >> 8));
            }
        } else {
            PutFixed(v.streams[0], {4096, 8192, 12288});
        }
        v.streams[4] = {191, 64, 191};
        WriteBytes(dir + "/v.spz", LegacyBytes(v));
        PointCloud d;
        ReadPointCloud(dir + "/v.spz", d);
        const float p1[3] = {1.5f, 2.0f, -0.0009765625f}, p2[3] = {1, -2, -3};
        for (int k = 0; k < 3; ++k) EXPECT_EQ(F(d, "positions")[k], (version == 1 ? p1 : p2)[k]);
        // Python: x = 191/127.5 - 1, y = 64/127.5 - 1, w = sqrt(1 - x^2 - y^2 - z^2)
        const double q[4] = {0.5058367512506398, 0.4980392156862745, 0.4980392156862745,
                             -0.4980392156862745};
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(F(d, "rot")[k], q[k], 1e-7) << version;
    }
}

TEST(SpzFormat, SHSignsKeepTheColourUnderTheAxisChange) {
    // A degree-3 splat whose 45 SH bytes are all different, stored in RUB. The reader's
    // coefficients evaluated along the RDF direction (x, -y, -z) must give the colour the
    // stored ones give along (x, y, z), and equal SHRotation's bands for diag(1, -1, -1).
    RawSpz r;
    r.version = 3;
    r.n = 1;
    r.degree = 3;
    PutFixed(r.streams[0], {0, 0, 0});
    r.streams[1] = {128};
    r.streams[2] = {128, 128, 128};
    r.streams[3] = {100, 100, 100};
    tests::AppendU32(r.streams[4], 3u << 30);
    float stored[45];
    for (int k = 0; k < 45; ++k) {
        r.streams[5].push_back(uint8_t(20 + 5 * k));
        stored[k] = float((20 + 5 * k - 128) / 128.0);
    }
    const std::string path = tests::TempDir() + "/sh.spz";
    WriteBytes(path, LegacyBytes(r));
    PointCloud c;
    ReadPointCloud(path, c);
    const float* rest = F(c, "f_rest");
    const float dc[3] = {0, 0, 0};
    std::mt19937 rng(1);
    std::normal_distribution<double> normal;
    for (int t = 0; t < 100; ++t) {
        double d[3] = {normal(rng), normal(rng), normal(rng)};
        const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (double& v : d) v /= len;
        const auto spz = geometry::EvaluateSH<double>(3, dc, stored, d[0], d[1], d[2]);
        const auto rdf = geometry::EvaluateSH<double>(3, dc, rest, d[0], -d[1], -d[2]);
        for (int ch = 0; ch < 3; ++ch) ASSERT_NEAR(rdf[ch], spz[ch], 1e-6) << t;
    }
    Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
    float rotated[45];
    std::copy(stored, stored + 45, rotated);
    geometry::SHRotation(flip, 3).Apply(rotated);
    for (int k = 0; k < 45; ++k) EXPECT_NEAR(rest[k], rotated[k], 1e-6) << k;
    // Coefficient signs for k = 0..14 under (x, -y, -z), derived from the basis' parity:
    const int signs[15] = {-1, -1, 1, -1, 1, 1, -1, 1, -1, 1, -1, -1, 1, -1, 1};
    for (int k = 0; k < 45; ++k) EXPECT_EQ(rest[k], signs[k / 3] * stored[k]) << k;

    // The writer applies the same signs: SH bytes on its grid (multiples of 8 for degree 1,
    // of 16 above), read and written again, come back as stored.
    for (int k = 0; k < 45; ++k)
        r.streams[5][k] = uint8_t(k < 9 ? 8 * ((5 * k) % 32) : 16 * (k % 16));
    WriteBytes(path, LegacyBytes(r));
    ReadPointCloud(path, c);
    const std::string out = tests::TempDir() + "/w.spz";
    WritePointCloud(out, c);
    const std::vector<Bytes> streams = V4Streams(ReadBytes(out));
    ASSERT_EQ(streams.size(), 6u);
    EXPECT_TRUE(streams[5] == r.streams[5]);
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
