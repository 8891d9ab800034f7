// PlayCanvas compressed PLY: the shared file against the PLY of the same capture within the
// quantisation, write -> read round trips within the bounds stated in CompressedPlyFormat.cpp,
// write -> read -> write identity, the writer's refusals. The shared file against values
// computed from its bytes: CompressedPlySharedFileTest.cpp; hand-built and malformed files:
// CompressedPlyHandBuiltTest.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>

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
            const double a_pos = FloatsOf(in, "positions")[i * 3 + f];
            note(0, std::abs(FloatsOf(out, "positions")[j * 3 + f] - a_pos),
                 (b[3 + f] - b[f]) / bits[f] / 2 + 1.2e-7 * std::abs(a_pos) + 1e-30);
            const double a_log =
                std::clamp(std::log(double(FloatsOf(in, "scale")[i * 3 + f])), -20.0, 20.0);
            note(1, std::abs(std::log(double(FloatsOf(out, "scale")[j * 3 + f])) - a_log),
                 (b[9 + f] - b[6 + f]) / bits[f] / 2 + 4e-6);
            const double a_col = 0.5 + kSH_C0 * FloatsOf(in, "f_dc")[i * 3 + f];
            note(2, std::abs(0.5 + kSH_C0 * FloatsOf(out, "f_dc")[j * 3 + f] - a_col),
                 (b[15 + f] - b[12 + f]) / 255 / 2 + 1e-6);
        }
        note(3,
             std::abs(Sigmoid(FloatsOf(out, "opacity")[j]) - Sigmoid(FloatsOf(in, "opacity")[i])),
             0.5 / 255 + 1e-7);
        // Rotation: the input normalised, its sign making the stored largest positive.
        const int largest = static_cast<int>(file.vertex[j * 4 + 1] >> 30);
        const float* qa = FloatsOf(in, "rot") + i * 4;
        const double norm = std::sqrt(double(qa[0]) * qa[0] + double(qa[1]) * qa[1] +
                                      double(qa[2]) * qa[2] + double(qa[3]) * qa[3]);
        const double sign = qa[largest] < 0 ? -1.0 : 1.0;
        for (int k = 0; k < 4; ++k) {
            const double error = std::abs(FloatsOf(out, "rot")[j * 4 + k] - sign * qa[k] / norm);
            note(4, error, (k == largest ? 3 : 1) * half_rot + 1e-6);
        }
        for (int c = 0; c < 3; ++c) {
            for (int k = 0; k < nc; ++k) {
                const uint8_t byte = file.sh[j * nc * 3 + c * nc + k];
                const double a_sh = FloatsOf(in, "f_rest")[(i * nc + k) * 3 + c];
                const double b_sh = FloatsOf(out, "f_rest")[(j * nc + k) * 3 + c];
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
// The shared file against the PLY and re-encoded.

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
    const PointCloud c = ReadCloud(tests::DataPath(kBikerCompressed));
    const PointCloud p = ReadCloud(tests::DataPath(kBikerPly));
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
            note(
                0,
                std::abs(FloatsOf(c, "positions")[i * 3 + f] - FloatsOf(p, "positions")[i * 3 + f]),
                (b[3 + f] - b[f]) / bits[f] / 2 + 0x1p-13 + 1e-7);
            note(1,
                 std::abs(std::max(std::log(double(FloatsOf(c, "scale")[i * 3 + f])), -10.0) -
                          std::log(double(FloatsOf(p, "scale")[i * 3 + f]))),
                 (b[9 + f] - b[6 + f]) / bits[f] / 2 + 1.0 / 32 + 1e-5);
            note(2, std::abs(FloatsOf(c, "f_dc")[i * 3 + f] - FloatsOf(p, "f_dc")[i * 3 + f]),
                 (b[15 + f] - b[12 + f]) / 255 / 2 / kSH_C0 + 0.5 / (255 * 0.15) + 1e-6);
        }
        note(3, std::abs(Sigmoid(FloatsOf(c, "opacity")[i]) - Sigmoid(FloatsOf(p, "opacity")[i])),
             0.5 / 255);
        const int largest = static_cast<int>(raw.vertex[i * 4 + 1] >> 30);
        const float* qc = FloatsOf(c, "rot") + i * 4;
        const float* qp = FloatsOf(p, "rot") + i * 4;
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
    WritePointCloud(path, ReadCloud(tests::DataPath(kBikerCompressed)));
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
    const PointCloud out = ReadCloud(first);
    const RawFile raw = ParseRaw(first);
    EXPECT_EQ(raw.num_chunks, (in.NumPoints() + 255) / 256);
    EXPECT_EQ(raw.num_rest_props, 3 * geometry::NumSHRestCoeffs(in.GaussianSplatGetSHOrder()));
    ExpectWithinQuantisation(in, out, raw, Identity(in.NumPoints()));

    WritePointCloud(second, out);
    EXPECT_TRUE(FileBytes(first) == FileBytes(second)) << "write -> read -> write changed the file";
    ExpectIdentical(out, ReadCloud(second));
}

TEST(CompressedPly, RoundTripBiker) {
    OPEN3D_REQUIRE_DATA(kBikerPly);
    RoundTrip(ReadCloud(tests::DataPath(kBikerPly)), "biker");
}

TEST(CompressedPly, RoundTripPcShortWithSHDegree3) {
    OPEN3D_REQUIRE_DATA(kPcShort);
    const PointCloud in = ReadCloud(tests::DataPath(kPcShort));
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
    const PointCloud out = ReadCloud(first);
    const RawFile raw = ParseRaw(first);
    ASSERT_EQ(out.NumPoints(), n);

    // Which input splat each output splat is: its grid cell.
    std::vector<int64_t> input_of_cell(n), perm(n);
    for (int64_t i = 0; i < n; ++i) input_of_cell[cell_of_input[i]] = i;
    std::vector<int> seen(n, 0);
    int64_t moved = 0;
    for (int64_t j = 0; j < n; ++j) {
        const float* p = FloatsOf(out, "positions") + j * 3;
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
        const float* p = FloatsOf(cloud, "positions");
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
    ExpectIdentical(out, ReadCloud(second));
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
        const PointCloud read = ReadCloud(first);
        WritePointCloud(second, read);
        EXPECT_TRUE(FileBytes(first) == FileBytes(second));
        ExpectIdentical(read, ReadCloud(second));
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
        const PointCloud out = ReadCloud(path);
        ASSERT_EQ(out.NumPoints(), n);
        EXPECT_EQ(out.GaussianSplatGetSHOrder(), 2);
    }
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

// Regenerates two fuzz seeds (run with --gtest_also_run_disabled_tests); the hand-built one is
// CompressedPlyHandBuiltTest.cpp's.
TEST(CompressedPly, DISABLED_WriteFuzzSeeds) {
    const std::string seeds = std::string(OPEN3D_TEST_SOURCE_DIR) + "/fuzz/seeds/";
    std::vector<int> cells;
    WritePointCloud(seeds + "two_chunks.compressed.ply", Head(ShuffledGridCloud(0, cells), 300));
    PointCloud sh3 = Head(ShuffledGridCloud(3, cells), 20);
    WritePointCloud(seeds + "sh3.compressed.ply", sh3);
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
