// PlayCanvas compressed PLY: the shared file against values computed independently, against
// the PLY of the same capture within the quantisation, write -> read round trips within the
// bounds stated in CompressedPlyFormat.cpp, write -> read -> write identity, hand-built files
// that pin the bit layout, and malformed files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>

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

constexpr const char* kBikerCompressed = "formats/biker.compressed.ply";
constexpr const char* kBikerPly = "biker/biker_152k.ply";
constexpr const char* kPcShort = "pc_short/pc_short.ply";

std::vector<uint8_t> FileBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

// The file parsed with nothing but the layout (chunk, vertex, optional sh, properties in the
// writer's order), independently of the reader under test.
struct RawFile {
    int64_t n = 0, num_chunks = 0;
    int num_rest_props = 0;    // properties of the sh element
    std::vector<float> chunk;  // 18 per chunk
    std::vector<uint32_t> vertex;
    std::vector<uint8_t> sh;
    const float* Chunk(int64_t i) const { return chunk.data() + (i / 256) * 18; }
};

RawFile ParseRaw(const std::string& path) {
    const std::vector<uint8_t> bytes = FileBytes(path);
    const std::string text(bytes.begin(), bytes.end());
    const size_t end = text.find("end_header\n");
    EXPECT_NE(end, std::string::npos);
    std::istringstream header(text.substr(0, end));
    RawFile raw;
    std::string line, current;
    int chunk_props = 0;
    while (std::getline(header, line)) {
        std::istringstream words(line);
        std::string keyword, a, b;
        words >> keyword >> a >> b;
        if (keyword == "element") {
            current = a;
            const int64_t count = std::stoll(b);
            if (a == "chunk") raw.num_chunks = count;
            if (a == "vertex") raw.n = count;
        } else if (keyword == "property") {
            if (current == "chunk") ++chunk_props;
            if (current == "sh") ++raw.num_rest_props;
        }
    }
    EXPECT_EQ(chunk_props, 18);
    const uint8_t* p = bytes.data() + end + 11;
    raw.chunk.resize(raw.num_chunks * 18);
    raw.vertex.resize(raw.n * 4);
    raw.sh.resize(raw.n * raw.num_rest_props);
    std::memcpy(raw.chunk.data(), p, raw.chunk.size() * 4);
    p += raw.chunk.size() * 4;
    std::memcpy(raw.vertex.data(), p, raw.vertex.size() * 4);
    p += raw.vertex.size() * 4;
    if (!raw.sh.empty()) std::memcpy(raw.sh.data(), p, raw.sh.size());
    return raw;
}

PointCloud Read(const std::string& path) {
    PointCloud cloud;
    ReadPointCloud(path, cloud);
    return cloud;
}

const float* F(const PointCloud& cloud, const char* name) {
    return cloud.GetPointAttr(name).Data<float>();
}

double Sigmoid(double v) { return 1.0 / (1.0 + std::exp(-v)); }

void ExpectIdentical(const PointCloud& a, const PointCloud& b) {
    ASSERT_EQ(a.NumPoints(), b.NumPoints());
    for (const char* name : {"positions", "scale", "rot", "opacity", "f_dc", "f_rest"}) {
        ASSERT_EQ(a.HasPointAttr(name), b.HasPointAttr(name)) << name;
        if (!a.HasPointAttr(name)) continue;
        const Tensor& ta = a.GetPointAttr(name);
        const Tensor& tb = b.GetPointAttr(name);
        ASSERT_EQ(ta.GetShape(), tb.GetShape()) << name;
        EXPECT_EQ(std::memcmp(ta.Data<float>(), tb.Data<float>(), ta.NumBytes()), 0)
            << name << " differs";
    }
}

// Checks `out` (read back from `file`) against `in`, splat out[j] being in[perm[j]], within
// the bounds stated at the top of CompressedPlyFormat.cpp.
void ExpectWithinQuantisation(const PointCloud& in, const PointCloud& out, const RawFile& file,
                              const std::vector<int64_t>& perm) {
    const int64_t n = out.NumPoints();
    ASSERT_EQ(in.NumPoints(), n);
    const int degree = in.GaussianSplatGetSHOrder();
    ASSERT_EQ(out.GaussianSplatGetSHOrder(), degree);
    const int nc = geometry::NumSHRestCoeffs(degree);
    const double bits[3] = {2047, 1023, 2047};
    const double half_rot = std::sqrt(2.0) / 1023 / 2;
    double worst[6] = {0, 0, 0, 0, 0, 0};  // ratio error / bound per attribute
    const char* names[6] = {"position", "log-scale", "colour", "alpha", "rotation", "f_rest"};
    auto note = [&](int attribute, double error, double bound) {
        worst[attribute] = std::max(worst[attribute], error / bound);
    };
    for (int64_t j = 0; j < n; ++j) {
        const int64_t i = perm[j];
        const float* b = file.Chunk(j);
        for (int f = 0; f < 3; ++f) {
            const double a_pos = F(in, "positions")[i * 3 + f];
            note(0, std::abs(F(out, "positions")[j * 3 + f] - a_pos),
                 (b[3 + f] - b[f]) / bits[f] / 2 + 1.2e-7 * std::abs(a_pos) + 1e-30);
            const double a_log =
                std::clamp(std::log(double(F(in, "scale")[i * 3 + f])), -20.0, 20.0);
            note(1, std::abs(std::log(double(F(out, "scale")[j * 3 + f])) - a_log),
                 (b[9 + f] - b[6 + f]) / bits[f] / 2 + 4e-6);
            const double a_col = 0.5 + kSH_C0 * F(in, "f_dc")[i * 3 + f];
            note(2, std::abs(0.5 + kSH_C0 * F(out, "f_dc")[j * 3 + f] - a_col),
                 (b[15 + f] - b[12 + f]) / 255 / 2 + 1e-6);
        }
        note(3, std::abs(Sigmoid(F(out, "opacity")[j]) - Sigmoid(F(in, "opacity")[i])),
             0.5 / 255 + 1e-7);
        // Rotation: the input normalised, its sign making the stored largest positive.
        const int largest = static_cast<int>(file.vertex[j * 4 + 1] >> 30);
        const float* qa = F(in, "rot") + i * 4;
        const double norm = std::sqrt(double(qa[0]) * qa[0] + double(qa[1]) * qa[1] +
                                      double(qa[2]) * qa[2] + double(qa[3]) * qa[3]);
        const double sign = qa[largest] < 0 ? -1.0 : 1.0;
        for (int k = 0; k < 4; ++k) {
            const double error = std::abs(F(out, "rot")[j * 4 + k] - sign * qa[k] / norm);
            note(4, error, (k == largest ? 3 : 1) * half_rot + 1e-6);
        }
        for (int c = 0; c < 3; ++c) {
            for (int k = 0; k < nc; ++k) {
                const uint8_t byte = file.sh[j * nc * 3 + c * nc + k];
                const double a_sh = F(in, "f_rest")[(i * nc + k) * 3 + c];
                const double b_sh = F(out, "f_rest")[(j * nc + k) * 3 + c];
                if (byte == 0 || byte == 255) {
                    note(5, std::abs(b_sh - std::clamp(a_sh, -4.0, 4.0)), 1.0 / 32 + 1e-6);
                } else {
                    note(5, std::abs(b_sh - a_sh), 1.0 / 64 + 1e-6);
                }
            }
        }
    }
    for (int k = 0; k < 6; ++k) {
        EXPECT_LE(worst[k], 1.0) << names[k] << ": worst error is " << worst[k]
                                 << " times its bound";
    }
}

std::vector<int64_t> Identity(int64_t n) {
    std::vector<int64_t> perm(n);
    for (int64_t i = 0; i < n; ++i) perm[i] = i;
    return perm;
}

// ---------------------------------------------------------------------------------------
// The shared file.

struct ExpectedSplat {
    int64_t index;
    float position[3], scale[3], rot[4], f_dc[3], opacity;
};

// Computed from the bytes alone with this Python (struct and math only), in ../shared/data:
//   f32 = lambda v: struct.unpack('<f', struct.pack('<f', v))[0]
//   d = open('formats/biker.compressed.ply', 'rb').read(); h = d.index(b'end_header\n') + 11
//   chunk = lambda c: struct.unpack_from('<18f', d, h + c * 72)
//   vert = lambda i: struct.unpack_from('<4I', d, h + 597 * 72 + i * 16)
//   un = lambda v, b: (v & ((1 << b) - 1)) / ((1 << b) - 1)
//   lerp = lambda a, b, t: a * (1 - t) + b * t
//   c = chunk(i // 256); p, r, s, col = vert(i); fields = [(21, 11), (11, 10), (0, 11)]
//   pos = [f32(lerp(c[k], c[3 + k], un(p >> sh, b))) for k, (sh, b) in enumerate(fields)]
//   scale = [f32(math.exp(f32(lerp(c[6 + k], c[9 + k], un(s >> sh, b)))))
//            for k, (sh, b) in enumerate(fields)]
//   f_dc = [f32((lerp(c[12 + k], c[15 + k], un(col >> (24 - 8 * k), 8)) - 0.5) / SH_C0)
//           for k in range(3)]
//   a = un(col, 8); opacity = f32(-math.log(1 / a - 1))
//   st = [(un(r >> sh, 10) - 0.5) * 2 ** 0.5 for sh in (20, 10, 0)]
//   rot = st[:]; rot.insert(r >> 30, math.sqrt(1 - sum(x * x for x in st)))  # (w, x, y, z)
const ExpectedSplat kBikerSplats[] = {
    {0,
     {-0.10453680157661438f, -2.3878982067108154f, -0.3608109951019287f},
     {0.0023136779200285673f, 0.014897788874804974f, 0.0008667604997754097f},
     {0.4610363841056824f, -0.06290001422166824f, 0.8848552107810974f, 0.022809896618127823f},
     {0.5478684902191162f, 0.5222843289375305f, 0.5681517720222473f},
     -2.577688455581665f},
    {1,
     {-0.10449791699647903f, -2.401226758956909f, -0.35535505414009094f},
     {0.0018251872388646007f, 0.031785935163497925f, 0.0007897504256106913f},
     {0.5370693802833557f, -0.08225386589765549f, 0.8388347029685974f, -0.033869240432977676f},
     {0.62809157371521f, 0.6290907263755798f, 0.6740944981575012f},
     -2.7725887298583984f},
    {255,
     {-0.1290137767791748f, -2.060115337371826f, -0.4440408945083618f},
     {0.004674970638006926f, 0.006069208960980177f, 0.002269479213282466f},
     {0.5025089383125305f, -0.28546929359436035f, 0.09469562768936157f, 0.8105706572532654f},
     {-1.3774865865707397f, -1.3601781129837036f, -1.3388174772262573f},
     -0.3728889524936676f},
    {256,
     {-0.13092470169067383f, -2.047135829925537f, -0.4464400112628937f},
     {0.010003495030105114f, 0.004301309119910002f, 0.00016215493087656796f},
     {0.9058474898338318f, -0.05322309210896492f, 0.38085615634918213f, 0.17764070630073547f},
     {-1.6601104736328125f, -1.65126633644104f, -1.6268891096115112f},
     -2.1756255626678467f},
    {76543,
     {0.156648188829422f, -1.3464927673339844f, -0.15543480217456818f},
     {0.0028675736393779516f, 0.0007153447950258851f, 0.002899527782574296f},
     {0.9859962463378906f, -0.08778353780508041f, -0.138933002948761f, -0.02833956852555275f},
     {-0.8893909454345703f, -0.8419008851051331f, -0.8761141300201416f},
     -3.4299468994140625f},
    {152745,
     {0.16716530919075012f, -0.6030639410018921f, 0.3288194239139557f},
     {0.0031036201398819685f, 0.007889961823821068f, 0.0004816018044948578f},
     {0.9981916546821594f, 0.040781330317258835f, -0.042163748294115067f, 0.013132970780134201f},
     {1.1197552680969238f, 1.0974349975585938f, 1.0597506761550903f},
     -2.8457396030426025f},
};

TEST(CompressedPly, SharedFileMatchesIndependentValues) {
    OPEN3D_REQUIRE_DATA(kBikerCompressed);
    const std::string path = tests::DataPath(kBikerCompressed);
    EXPECT_EQ(DetectPointCloudFileFormat(path), PointCloudFileFormat::kCompressedPly);
    PointCloud cloud;
    const ReadPointCloudReport report = ReadPointCloud(path, cloud);
    ASSERT_EQ(cloud.NumPoints(), 152746);
    EXPECT_EQ(cloud.GaussianSplatGetSHOrder(), 0);
    EXPECT_EQ(report.trailing_bytes, 0);
    EXPECT_EQ(report.dropped_non_finite, 0);
    for (const ExpectedSplat& e : kBikerSplats) {
        SCOPED_TRACE("splat " + std::to_string(e.index));
        const int64_t i = e.index;
        for (int c = 0; c < 3; ++c) {
            EXPECT_FLOAT_EQ(F(cloud, "positions")[i * 3 + c], e.position[c]);
            EXPECT_FLOAT_EQ(F(cloud, "scale")[i * 3 + c], e.scale[c]);
            EXPECT_FLOAT_EQ(F(cloud, "f_dc")[i * 3 + c], e.f_dc[c]);
        }
        for (int c = 0; c < 4; ++c) EXPECT_FLOAT_EQ(F(cloud, "rot")[i * 4 + c], e.rot[c]);
        EXPECT_FLOAT_EQ(F(cloud, "opacity")[i], e.opacity);
    }
}

// biker_152k.ply is the same capture, splat for splat in the same order, but it is itself
// decoded from SPZ: positions lie on a 1/4096 grid, log-scales on a 1/16 grid floored at -10,
// f_dc on SPZ's colour grid (f_dc * 0.15 + 0.5) * 255, rotations are SPZ's smallest-three with
// 9-bit magnitudes (checked with Python on the file). Both files quantise the same original,
// so each bound is the compressed file's half quantum plus SPZ's half step:
//   position   |c - p| <= (max - min) / (2^b - 1) / 2 + 2^-13, b = 11, 10, 11
//   log-scale  |max(log c, -10) - log p| <= (max - min) / (2^b - 1) / 2 + 1/32
//   f_dc       |c - p| <= (max_c - min_c) / 255 / 2 / SH_C0 + 0.5 / (255 * 0.15)
//   alpha      |sigmoid(c) - sigmoid(p)| <= 0.5 / 255 (both store the same 8-bit alpha)
//   rotation   sign-aligned, normalised: the three stored components <= h + 3 s, the
//              largest <= 3 (h + s), h = sqrt(2) / 1023 / 2, s = sqrt(1/2) / 511 / 2
// (the reconstructed component's error is at most 3 times the stored ones' for components
// of a unit quaternion whose largest is >= 1/2).
TEST(CompressedPly, BikerMatchesPlyOfTheSameCapture) {
    OPEN3D_REQUIRE_DATA(kBikerCompressed);
    OPEN3D_REQUIRE_DATA(kBikerPly);
    const PointCloud c = Read(tests::DataPath(kBikerCompressed));
    const PointCloud p = Read(tests::DataPath(kBikerPly));
    const RawFile raw = ParseRaw(tests::DataPath(kBikerCompressed));
    ASSERT_EQ(raw.num_chunks, 597);
    ASSERT_EQ(c.NumPoints(), p.NumPoints());
    const double bits[3] = {2047, 1023, 2047};
    const double h = std::sqrt(2.0) / 1023 / 2, s = std::sqrt(0.5) / 511 / 2;
    double worst[5] = {0, 0, 0, 0, 0};
    auto note = [&](int k, double error, double bound) {
        worst[k] = std::max(worst[k], error / bound);
    };
    for (int64_t i = 0; i < c.NumPoints(); ++i) {
        const float* b = raw.Chunk(i);
        for (int f = 0; f < 3; ++f) {
            note(0, std::abs(F(c, "positions")[i * 3 + f] - F(p, "positions")[i * 3 + f]),
                 (b[3 + f] - b[f]) / bits[f] / 2 + 0x1p-13 + 1e-7);
            note(1,
                 std::abs(std::max(std::log(double(F(c, "scale")[i * 3 + f])), -10.0) -
                          std::log(double(F(p, "scale")[i * 3 + f]))),
                 (b[9 + f] - b[6 + f]) / bits[f] / 2 + 1.0 / 32 + 1e-5);
            note(2, std::abs(F(c, "f_dc")[i * 3 + f] - F(p, "f_dc")[i * 3 + f]),
                 (b[15 + f] - b[12 + f]) / 255 / 2 / kSH_C0 + 0.5 / (255 * 0.15) + 1e-6);
        }
        note(3, std::abs(Sigmoid(F(c, "opacity")[i]) - Sigmoid(F(p, "opacity")[i])), 0.5 / 255);
        const int largest = static_cast<int>(raw.vertex[i * 4 + 1] >> 30);
        const float* qc = F(c, "rot") + i * 4;
        const float* qp = F(p, "rot") + i * 4;
        double dot = 0, norm = 0;
        for (int k = 0; k < 4; ++k) {
            dot += double(qc[k]) * qp[k];
            norm += double(qp[k]) * qp[k];
        }
        const double scale = (dot < 0 ? -1.0 : 1.0) / std::sqrt(norm);
        for (int k = 0; k < 4; ++k) {
            note(4, std::abs(qc[k] - qp[k] * scale), k == largest ? 3 * (h + s) : h + 3 * s);
        }
    }
    const char* names[5] = {"position", "log-scale", "f_dc", "alpha", "rotation"};
    for (int k = 0; k < 5; ++k) {
        EXPECT_LE(worst[k], 1.0) << names[k] << ": worst error is " << worst[k]
                                 << " times its bound";
    }
}

// Our writer against the reference writer: decoding SuperSplat's file and encoding it again
// gives back every packed word. The position and colour bounds come back as the same floats;
// a log-scale bound may move by an ulp where SuperSplat's (the log of the source's value) is
// not the float EncodeLogScale gives for the decoded scale (one does in this file).
TEST(CompressedPly, ReencodingTheSharedFileReproducesItsCodes) {
    OPEN3D_REQUIRE_DATA(kBikerCompressed);
    const std::string path = tests::TempDir() + "/biker_again.compressed.ply";
    WritePointCloud(path, Read(tests::DataPath(kBikerCompressed)));
    const RawFile ours = ParseRaw(path);
    const RawFile theirs = ParseRaw(tests::DataPath(kBikerCompressed));
    ASSERT_EQ(ours.n, theirs.n);
    ASSERT_EQ(ours.num_chunks, theirs.num_chunks);
    int64_t words_differing = 0, bounds_moved = 0;
    for (size_t k = 0; k < ours.vertex.size(); ++k)
        words_differing += ours.vertex[k] != theirs.vertex[k];
    for (size_t k = 0; k < ours.chunk.size(); ++k) {
        const float a = ours.chunk[k], b = theirs.chunk[k];
        if (a == b) continue;
        ++bounds_moved;
        EXPECT_TRUE(k % 18 >= 6 && k % 18 < 12) << "bound " << k % 18 << " of chunk " << k / 18;
        EXPECT_LE(std::abs(a - b), std::abs(std::nextafter(b, INFINITY) - b)) << k;
    }
    EXPECT_EQ(words_differing, 0);
    EXPECT_LE(bounds_moved, 5);
}

// ---------------------------------------------------------------------------------------
// Round trips.

// Writes `in`, reads it back, checks the bounds (splats in the input order: the writer keeps
// an order that is already spatially coherent), then writes the read cloud again: the same
// bytes, and the same values when read.
void RoundTrip(const PointCloud& in, const std::string& name) {
    const std::string dir = tests::TempDir();
    const std::string first = dir + "/" + name + ".compressed.ply";
    const std::string second = dir + "/" + name + "_again.compressed.ply";
    WritePointCloud(first, in);
    const PointCloud out = Read(first);
    const RawFile raw = ParseRaw(first);
    EXPECT_EQ(raw.num_chunks, (in.NumPoints() + 255) / 256);
    EXPECT_EQ(raw.num_rest_props, 3 * geometry::NumSHRestCoeffs(in.GaussianSplatGetSHOrder()));
    ExpectWithinQuantisation(in, out, raw, Identity(in.NumPoints()));

    WritePointCloud(second, out);
    EXPECT_TRUE(FileBytes(first) == FileBytes(second)) << "write -> read -> write changed the file";
    ExpectIdentical(out, Read(second));
}

TEST(CompressedPly, RoundTripBiker) {
    OPEN3D_REQUIRE_DATA(kBikerPly);
    RoundTrip(Read(tests::DataPath(kBikerPly)), "biker");
}

TEST(CompressedPly, RoundTripPcShortWithSHDegree3) {
    OPEN3D_REQUIRE_DATA(kPcShort);
    const PointCloud in = Read(tests::DataPath(kPcShort));
    ASSERT_EQ(in.GaussianSplatGetSHOrder(), 3);
    RoundTrip(in, "pc_short");
}

// A cloud on a jittered 16 x 16 x 12 grid (cell = splat id), shuffled: the writer sorts it into
// Morton order, so the splats come back in another order; the grid cell names each one.
PointCloud ShuffledGridCloud(int degree, std::vector<int>& cell_of_input) {
    const int n = 16 * 16 * 12;
    std::mt19937 rng(7);
    std::vector<int> cells(n);
    for (int i = 0; i < n; ++i) cells[i] = i;
    std::shuffle(cells.begin(), cells.end(), rng);
    std::uniform_real_distribution<float> jitter(-0.2f, 0.2f), log_scale(-7.0f, 1.0f);
    std::normal_distribution<float> normal(0.0f, 1.0f);
    const int nc = geometry::NumSHRestCoeffs(degree);
    std::vector<float> pos(n * 3), scale(n * 3), rot(n * 4), opacity(n), f_dc(n * 3),
        f_rest(n * nc * 3);
    for (int i = 0; i < n; ++i) {
        const int cell = cells[i];
        pos[i * 3 + 0] = 3.0f + cell % 16 + jitter(rng);
        pos[i * 3 + 1] = -5.0f + (cell / 16) % 16 + jitter(rng);
        pos[i * 3 + 2] = 0.5f + cell / 256 + jitter(rng);
        for (int c = 0; c < 3; ++c) scale[i * 3 + c] = DecodeLogScale(log_scale(rng));
        for (int c = 0; c < 4; ++c) rot[i * 4 + c] = normal(rng);
        opacity[i] = 4.0f * normal(rng);
        for (int c = 0; c < 3; ++c) f_dc[i * 3 + c] = normal(rng);
        for (int k = 0; k < nc * 3; ++k) f_rest[i * nc * 3 + k] = 1.5f * normal(rng);
    }
    // Edge cases: a zero scale, saturated opacities, SH beyond +-4.
    scale[5] = 0.0f;
    opacity[7] = 60.0f;
    opacity[8] = -60.0f;
    if (nc > 0) {
        f_rest[0] = 7.0f;
        f_rest[1] = -9.0f;
    }
    cell_of_input = cells;
    PointCloud cloud(Tensor::FromVector(pos, {n, 3}));
    cloud.SetPointAttr("scale", Tensor::FromVector(scale, {n, 3}));
    cloud.SetPointAttr("rot", Tensor::FromVector(rot, {n, 4}));
    cloud.SetPointAttr("opacity", Tensor::FromVector(opacity, {n, 1}));
    cloud.SetPointAttr("f_dc", Tensor::FromVector(f_dc, {n, 3}));
    if (nc > 0) cloud.SetPointAttr("f_rest", Tensor::FromVector(f_rest, {n, nc, 3}));
    return cloud;
}

// The first n splats of a cloud.
PointCloud Head(const PointCloud& cloud, int64_t n) {
    auto head = [&](const char* name) {
        const Tensor& t = cloud.GetPointAttr(name);
        core::SizeVector shape = t.GetShape();
        const int64_t width = t.NumElements() / shape[0];
        shape[0] = n;
        const float* src = t.Data<float>();
        return Tensor::FromVector(std::vector<float>(src, src + n * width), shape);
    };
    PointCloud out(head("positions"));
    for (const char* name : {"scale", "rot", "opacity", "f_dc", "f_rest"}) {
        if (cloud.HasPointAttr(name)) out.SetPointAttr(name, head(name));
    }
    return out;
}

TEST(CompressedPly, ShuffledInputIsSortedAndRoundTrips) {
    std::vector<int> cell_of_input;
    const PointCloud in = ShuffledGridCloud(1, cell_of_input);
    const int64_t n = in.NumPoints();
    const std::string dir = tests::TempDir();
    const std::string first = dir + "/grid.compressed.ply";
    WritePointCloud(first, in);
    const PointCloud out = Read(first);
    const RawFile raw = ParseRaw(first);
    ASSERT_EQ(out.NumPoints(), n);

    // Which input splat each output splat is: its grid cell.
    std::vector<int64_t> input_of_cell(n), perm(n);
    for (int64_t i = 0; i < n; ++i) input_of_cell[cell_of_input[i]] = i;
    std::vector<int> seen(n, 0);
    int64_t moved = 0;
    for (int64_t j = 0; j < n; ++j) {
        const float* p = F(out, "positions") + j * 3;
        const int cx = int(std::lround(p[0] - 3.0f)), cy = int(std::lround(p[1] + 5.0f));
        const int cz = int(std::lround(p[2] - 0.5f));
        ASSERT_TRUE(cx >= 0 && cx < 16 && cy >= 0 && cy < 16 && cz >= 0 && cz < 12) << j;
        const int cell = cx + 16 * cy + 256 * cz;
        ASSERT_EQ(seen[cell]++, 0) << "two splats read back in grid cell " << cell;
        perm[j] = input_of_cell[cell];
        moved += perm[j] != j;
    }
    EXPECT_GT(moved, n / 2) << "the shuffled input was not reordered";
    // Morton order makes the chunks compact: their summed extents are well below those of
    // the chunks the shuffled input order would make (each about the whole grid).
    auto summed_extent = [](const PointCloud& cloud) {
        double extent = 0;
        const float* p = F(cloud, "positions");
        for (int64_t begin = 0; begin < cloud.NumPoints(); begin += 256) {
            const int64_t end = std::min(cloud.NumPoints(), begin + 256);
            for (int f = 0; f < 3; ++f) {
                float lo = INFINITY, hi = -INFINITY;
                for (int64_t i = begin; i < end; ++i) {
                    lo = std::min(lo, p[i * 3 + f]);
                    hi = std::max(hi, p[i * 3 + f]);
                }
                extent += hi - lo;
            }
        }
        return extent;
    };
    EXPECT_LT(summed_extent(out), 0.6 * summed_extent(in)) << "chunks are not compact";
    ExpectWithinQuantisation(in, out, raw, perm);

    // Writing what was read keeps its (now coherent) order and reproduces the file.
    const std::string second = dir + "/grid_again.compressed.ply";
    WritePointCloud(second, out);
    EXPECT_TRUE(FileBytes(first) == FileBytes(second));
    ExpectIdentical(out, Read(second));
}

// Values where decoding is many-to-one or the reference's choices are fragile: zero, unit and
// huge scales (log-scale near 0 and clamped at +-20), dark and saturated colours, tiny and
// zero position ranges, far-off coordinates, saturated opacities, quaternions with ties for
// the largest component. Write -> read -> write must still give the same file.
TEST(CompressedPly, WriteReadWriteIsIdenticalOnHardValues) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::normal_distribution<float> normal(0.0f, 1.0f);
    const std::string dir = tests::TempDir();
    for (int trial = 0; trial < 6; ++trial) {
        SCOPED_TRACE("trial " + std::to_string(trial));
        std::vector<int> cells;
        PointCloud cloud = Head(ShuffledGridCloud(trial % 4, cells), 600 + 97 * trial);
        const int64_t n = cloud.NumPoints();
        float* p = cloud.GetPointAttr("positions").Data<float>();
        float* s = cloud.GetPointAttr("scale").Data<float>();
        float* q = cloud.GetPointAttr("rot").Data<float>();
        float* o = cloud.GetPointAttr("opacity").Data<float>();
        float* dc = cloud.GetPointAttr("f_dc").Data<float>();
        const float offsets[6] = {0.0f, 1e4f, -3e5f, 1e-3f, 7.0f, -2.5e3f};
        const float ties[4][4] = {{0.5f, 0.5f, 0.5f, 0.5f},
                                  {0.70710677f, 0.70710677f, 0.0f, 0.0f},
                                  {0.0f, -0.70710677f, 0.70710677f, 0.0f},
                                  {-0.5f, 0.5f, -0.5f, 0.5f}};
        for (int64_t i = 0; i < n; ++i) {
            for (int c = 0; c < 3; ++c) {
                p[i * 3 + c] = p[i * 3 + c] * (trial == 3 ? 1e-5f : 1.0f) + offsets[trial];
                const float pick = unit(rng);
                if (pick < 0.1f)
                    s[i * 3 + c] = 0.0f;
                else if (pick < 0.2f)
                    s[i * 3 + c] = 1.0f;
                else if (pick < 0.25f)
                    s[i * 3 + c] = 1e12f;
                else if (pick < 0.35f)
                    s[i * 3 + c] = DecodeLogScale(0.05f * normal(rng));
                const float colour = unit(rng);
                if (colour < 0.2f)
                    dc[i * 3 + c] = -1.77f + 0.01f * unit(rng);  // nearly black
                else if (colour < 0.25f)
                    dc[i * 3 + c] = 5.0f * normal(rng);
            }
            if (unit(rng) < 0.1f) o[i] = unit(rng) < 0.5f ? 50.0f : -50.0f;
            if (unit(rng) < 0.2f) std::copy(ties[i % 4], ties[i % 4] + 4, q + i * 4);
        }
        for (int64_t i = 256; i < std::min<int64_t>(n, 512); ++i) {  // chunk 1: one position
            for (int c = 0; c < 3; ++c) p[i * 3 + c] = p[256 * 3 + c];
        }
        const std::string first = dir + "/hard.compressed.ply";
        const std::string second = dir + "/hard_again.compressed.ply";
        WritePointCloud(first, cloud);
        const PointCloud read = Read(first);
        WritePointCloud(second, read);
        EXPECT_TRUE(FileBytes(first) == FileBytes(second));
        ExpectIdentical(read, Read(second));
    }
}

TEST(CompressedPly, PartialChunkAndSingleSplat) {
    std::vector<int> cells;
    const PointCloud grid = ShuffledGridCloud(2, cells);
    for (int64_t n : {int64_t(1), int64_t(255), int64_t(257)}) {
        SCOPED_TRACE(n);
        const PointCloud in = Head(grid, n);
        const std::string path = tests::TempDir() + "/partial.compressed.ply";
        WritePointCloud(path, in);
        const PointCloud out = Read(path);
        ASSERT_EQ(out.NumPoints(), n);
        EXPECT_EQ(out.GaussianSplatGetSHOrder(), 2);
    }
}

TEST(CompressedPly, EmptyCloud) {
    PointCloud in(Tensor::Empty({0, 3}, core::Dtype::Float32));
    for (auto [name, width] : {std::pair{"scale", 3}, std::pair{"rot", 4}, std::pair{"opacity", 1},
                               std::pair{"f_dc", 3}}) {
        in.SetPointAttr(name, Tensor::Empty({0, width}, core::Dtype::Float32));
    }
    const std::string path = tests::TempDir() + "/empty.compressed.ply";
    WritePointCloud(path, in);
    EXPECT_EQ(Read(path).NumPoints(), 0);
}

TEST(CompressedPly, WriterRefusesWhatItCannotStore) {
    std::vector<int> cells;
    const std::string path = tests::TempDir() + "/bad.compressed.ply";
    {
        PointCloud cloud = ShuffledGridCloud(0, cells);
        cloud.GetPointAttr("positions").Data<float>()[3 * 10 + 1] = NAN;
        try {
            WritePointCloud(path, cloud);
            FAIL() << "no error";
        } catch (const core::Open3DError& e) {
            EXPECT_NE(std::string(e.what()).find("splat 10 has a non-finite position"),
                      std::string::npos)
                << e.what();
        }
    }
    {
        PointCloud cloud = ShuffledGridCloud(0, cells);
        float* rot = cloud.GetPointAttr("rot").Data<float>();
        std::fill(rot + 4 * 3, rot + 4 * 4, 0.0f);
        EXPECT_THROW(WritePointCloud(path, cloud), core::Open3DError);
    }
    {
        PointCloud cloud = ShuffledGridCloud(0, cells);
        cloud.GetPointAttr("scale").Data<float>()[0] = -1.0f;
        EXPECT_THROW(WritePointCloud(path, cloud), core::Open3DError);
    }
    PointCloud plain(Tensor({2, 3}, core::Dtype::Float32));
    EXPECT_THROW(WritePointCloud(path, plain), core::Open3DError);
}

// ---------------------------------------------------------------------------------------
// Hand-built files.

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
        const PointCloud c = Read(path);
        ASSERT_EQ(c.NumPoints(), 2);
        const float* p = F(c, "positions");
        EXPECT_FLOAT_EQ(p[0], 5);
        EXPECT_FLOAT_EQ(p[1], 7);
        EXPECT_FLOAT_EQ(p[2], 9);
        EXPECT_FLOAT_EQ(p[3], 2047);
        EXPECT_FLOAT_EQ(p[4], 1023);
        EXPECT_FLOAT_EQ(p[5], 0);
        const float* s = F(c, "scale");
        EXPECT_FLOAT_EQ(s[0], std::exp(1.0f));
        EXPECT_FLOAT_EQ(s[1], std::exp(2.0f));
        EXPECT_FLOAT_EQ(s[2], std::exp(-2.0f));
        EXPECT_FLOAT_EQ(s[3], 1.0f);
        const float* q = F(c, "rot");
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
        const float* dc = F(c, "f_dc");
        auto f_dc = [](double colour) { return float((colour - 0.5) / kSH_C0); };
        EXPECT_FLOAT_EQ(dc[0], f_dc(colour_bounds ? 0.75 : 1.0));
        EXPECT_FLOAT_EQ(dc[1], f_dc(colour_bounds ? 0.5 : 0.0));
        EXPECT_FLOAT_EQ(dc[2], f_dc(colour_bounds ? 0.2 : 0.2));
        EXPECT_FLOAT_EQ(dc[3], f_dc(colour_bounds ? 0.25 : 0.0));
        EXPECT_FLOAT_EQ(dc[4], f_dc(1.0));
        EXPECT_FLOAT_EQ(dc[5], f_dc(1.0));
        const float* o = F(c, "opacity");
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
    const PointCloud c = Read(path);
    ASSERT_EQ(c.GaussianSplatGetSHOrder(), 1);
    const float* rest = F(c, "f_rest");  // [1, 3, 3]: f_rest_[ch * 3 + k] -> rest[k * 3 + ch]
    auto expect = [](uint8_t b) {
        return b == 0 ? -4.0f : b == 255 ? 4.0f : float(((b + 0.5) / 256 - 0.5) * 8);
    };
    for (int ch = 0; ch < 3; ++ch) {
        for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(rest[k * 3 + ch], expect(bytes[ch * 3 + k]));
    }
}

// Every malformed file must fail with an Open3DError naming the file and what is wrong.
void ExpectReadError(const std::string& path, std::initializer_list<const char*> fragments) {
    PointCloud cloud;
    try {
        ReadPointCloud(path, cloud);
        ADD_FAILURE() << "no error for " << path;
    } catch (const core::Open3DError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(path), std::string::npos) << message;
        for (const char* fragment : fragments) {
            EXPECT_NE(message.find(fragment), std::string::npos)
                << "'" << fragment << "' not in: " << message;
        }
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
TEST(CompressedPly, DISABLED_WriteFuzzSeeds) {
    const std::string seeds = std::string(OPEN3D_TEST_SOURCE_DIR) + "/fuzz/seeds/";
    std::vector<int> cells;
    WritePointCloud(seeds + "two_chunks.compressed.ply", Head(ShuffledGridCloud(0, cells), 300));
    PointCloud sh3 = Head(ShuffledGridCloud(3, cells), 20);
    WritePointCloud(seeds + "sh3.compressed.ply", sh3);
    TwoSplats(false).Write(seeds + "no_colour_bounds.compressed.ply");
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
