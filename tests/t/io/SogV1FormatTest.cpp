// PlayCanvas SOG version 1 ("SOGS": per-attribute mins / maxs instead of codebooks), built
// here from known splat values with the project's WebP encoder and zip writer, as the v1
// writers (splat-transform's write-sogs.ts of mid-2025, playcanvas/sogs) laid it out; decoded
// values checked against a decode written here from the layout and against the known values
// within the quantisation step. Also malformed v1 files failing with clean errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "SogV1TestFiles.h"
#include "TestUtility.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using namespace sogv1;

const float* F(const PointCloud& c, const char* attr) { return c.GetPointAttr(attr).Data<float>(); }

// One hand-worked splat (2 x 1 images; texel 1 is padding), SH degree 1, every value chosen so
// that the decode is simple arithmetic:
//   means: x code 65535 -> n = maxs = ln 3 -> x = e^(ln 3) - 1 = 2; y code 0 -> n = -2 ->
//   y = -(e^2 - 1); z: mins = maxs = ln 2 -> z = 1 whatever the code (0x1234 here).
//   quats (0, 255, 128, 254): mode 2, y omitted; w = (0 / 255 * 2 - 1) / sqrt 2 = -1 / sqrt 2,
//   x = +1 / sqrt 2, z = (128 / 255 * 2 - 1) / sqrt 2 = 1 / (255 sqrt 2); y = sqrt(max(0,
//   1 - w^2 - x^2 - z^2)) = 0; the reader normalises: divided by sqrt(1 + z^2).
//   scales (0, 255, 51) in [-3, 1], [-2, 2], [-1, 3]: logs -3, 2, -1 + 4 * 0.2 = -0.2.
//   sh0 (0, 255, 51, 204) in [-1, 1] x 3, [-5, 5]: f_dc -1, 1, -0.6; opacity logit -5 + 8 = 3.
//   shN [-0.5, 0.5], label 1 (R 1, G 0): entry 1 = texels 3..5 of row 0, bytes (0, 255, 51),
//   (255, 0, 102), (51, 102, 255) -> (-0.5, 0.5, -0.3), (0.5, -0.5, -0.1), (-0.3, -0.1, 0.5)
//   for coefficients 0, 1, 2 in R, G, B.
V1Sog HandWorked() {
    V1Sog sog;
    sog.meta = {{"means",
                 {{"shape", Json::array({1, 3})},
                  {"dtype", "float32"},
                  {"mins", {0.0, -2.0, std::log(2.0)}},
                  {"maxs", {std::log(3.0), 2.0, std::log(2.0)}},
                  {"files", Json::array({"means_l.webp", "means_u.webp"})}}},
                {"scales",
                 {{"shape", Json::array({1, 3})},
                  {"mins", {-3.0, -2.0, -1.0}},
                  {"maxs", {1.0, 2.0, 3.0}},
                  {"files", Json::array({"scales.webp"})}}},
                {"quats",
                 {{"shape", Json::array({1, 4})},
                  {"encoding", "quaternion_packed"},
                  {"files", Json::array({"quats.webp"})}}},
                {"sh0",
                 {{"shape", Json::array({1, 1, 4})},
                  {"mins", {-1.0, -1.0, -1.0, -5.0}},
                  {"maxs", {1.0, 1.0, 1.0, 5.0}},
                  {"files", Json::array({"sh0.webp"})}}},
                {"shN",
                 {{"shape", Json::array({1, 3})},
                  {"mins", -0.5},
                  {"maxs", 0.5},
                  {"quantization", 8},
                  {"files", Json::array({"shN_centroids.webp", "shN_labels.webp"})}}}};
    const auto set = [&](const char* name, std::array<uint8_t, 4> rgba) {
        Rgba8Image image = Blank(2, 1);
        std::copy(rgba.begin(), rgba.end(), image.rgba.begin());
        sog.images[name] = image;
    };
    set("means_l.webp", {255, 0, 0x34, 255});
    set("means_u.webp", {255, 0, 0x12, 255});
    set("quats.webp", {0, 255, 128, 254});
    set("scales.webp", {0, 255, 51, 255});
    set("sh0.webp", {0, 255, 51, 204});
    set("shN_labels.webp", {1, 0, 0, 255});
    Rgba8Image centroids = Blank(64 * 3, 1);
    const uint8_t entry1[3][3] = {{0, 255, 51}, {255, 0, 102}, {51, 102, 255}};
    for (int j = 0; j < 3; ++j) {
        for (int c = 0; c < 3; ++c) centroids.rgba[(3 + j) * 4 + c] = entry1[j][c];
    }
    sog.images["shN_centroids.webp"] = centroids;
    return sog;
}

TEST(SogV1Format, HandWorkedSplat) {
    const std::string path = Write(HandWorked(), tests::TempDir() + "/hand.sog");
    EXPECT_EQ(DetectPointCloudFileFormat(path), PointCloudFileFormat::kSog);
    const PointCloud cloud = Read(path);
    ASSERT_EQ(cloud.NumPoints(), 1);
    ASSERT_TRUE(cloud.HasPointAttr("f_rest"));
    ASSERT_EQ(cloud.GetPointAttr("f_rest").GetShape(), core::SizeVector({1, 3, 3}));
    // float32 rounding of values below 10: 1e-6 absolute, relative for e^2.
    const double pos[3] = {2.0, -(std::exp(2.0) - 1.0), 1.0};
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(F(cloud, "positions")[a], pos[a], 1e-6) << a;
    const double z = 1.0 / (255.0 * kSqrt2), norm = std::sqrt(1.0 + z * z);
    const double rot[4] = {-1.0 / kSqrt2 / norm, 1.0 / kSqrt2 / norm, 0.0, z / norm};
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(F(cloud, "rot")[c], rot[c], 1e-6) << c;
    const double log_scale[3] = {-3.0, 2.0, -0.2};
    for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(F(cloud, "scale")[a], std::exp(log_scale[a]), 1e-6 * std::exp(log_scale[a]));
    }
    const double dc[3] = {-1.0, 1.0, -0.6};
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(F(cloud, "f_dc")[c], dc[c], 1e-6) << c;
    EXPECT_NEAR(F(cloud, "opacity")[0], 3.0, 1e-6);
    const double rest[9] = {-0.5, 0.5, -0.3, 0.5, -0.5, -0.1, -0.3, -0.1, 0.5};
    for (int k = 0; k < 9; ++k) EXPECT_NEAR(F(cloud, "f_rest")[k], rest[k], 1e-6) << k;
}

std::vector<double> Nums(const Json& v) { return v.get<std::vector<double>>(); }

// Checks `cloud` against (a) a decode of the sog's bytes written here from the layout (the
// engine's formulas: lerp(lo, hi, byte / 255), 16-bit means, the quaternion mode switch),
// to float32 rounding, and (b) the known values within the quantisation step. Bounds of (b):
// - position: the 16-bit code is rounded, so |LogT(x') - LogT(x)| <= step / 2 with step =
//   (max - min) / 65535 of that axis; plus 1e-6 for the float32 rounding of x'.
// - log-scale, f_dc, opacity logit, SH: the byte is rounded: error <= (max - min) / 255 / 2
//   of that channel (of the whole palette for SH); plus 1e-6 for float32.
// - rotation: each stored component is rounded to steps of 2 / (255 sqrt 2), error <=
//   0.00278; the omitted one d = sqrt(1 - s) (d >= 1/2) moves by <= |ds| / (2 d) <= |ds| with
//   |ds| <= 2 * 1.5 * 0.00278 + 3 * 0.00278^2 < 0.0084 (the three sum to at most sqrt(3 *
//   3/4) = 1.5 in absolute value): 0.0085 per component, the known quaternion having its
//   largest component positive.
void ExpectDecodes(const PointCloud& cloud, const V1Sog& sog, const Truth& t) {
    ASSERT_EQ(cloud.NumPoints(), t.n);
    const int nc = NumRest(t.degree);
    if (t.degree > 0) {
        ASSERT_EQ(cloud.GetPointAttr("f_rest").GetShape(), core::SizeVector({t.n, nc, 3}));
    } else {
        EXPECT_FALSE(cloud.HasPointAttr("f_rest"));
    }
    const Json& m = sog.meta;
    const std::vector<double> pmin = Nums(m["means"]["mins"]), pmax = Nums(m["means"]["maxs"]);
    const std::vector<double> smin = Nums(m["scales"]["mins"]), smax = Nums(m["scales"]["maxs"]);
    const std::vector<double> cmin = Nums(m["sh0"]["mins"]), cmax = Nums(m["sh0"]["maxs"]);
    auto px = [&](const char* name, int64_t i) { return &sog.images.at(name).rgba[i * 4]; };
    double worst_rot = 0;
    for (int64_t i = 0; i < t.n; ++i) {
        const uint8_t *lo = px("means_l.webp", i), *hi = px("means_u.webp", i);
        for (int a = 0; a < 3; ++a) {
            const double n = Lerp(pmin[a], pmax[a], (lo[a] + 256.0 * hi[a]) / 65535.0);
            const double x = F(cloud, "positions")[i * 3 + a];
            EXPECT_NEAR(x, UnLogT(n), 1e-6 * std::max(1.0, std::abs(x))) << i;
            EXPECT_LE(std::abs(LogT(x) - LogT(t.pos[i * 3 + a])),
                      (pmax[a] - pmin[a]) / 65535 / 2 + 1e-6)
                << i;
            const double ls = Lerp(smin[a], smax[a], px("scales.webp", i)[a] / 255.0);
            const double s = F(cloud, "scale")[i * 3 + a];
            EXPECT_NEAR(s, std::exp(ls), 1e-6 * std::exp(ls)) << i;
            EXPECT_LE(std::abs(std::log(s) - t.log_scale[i * 3 + a]),
                      (smax[a] - smin[a]) / 255 / 2 + 1e-6)
                << i;
        }
        for (int c = 0; c < 4; ++c) {
            const double v = Lerp(cmin[c], cmax[c], px("sh0.webp", i)[c] / 255.0);
            const double got = c < 3 ? F(cloud, "f_dc")[i * 3 + c] : F(cloud, "opacity")[i];
            const double truth = c < 3 ? t.dc[i * 3 + c] : t.logit[i];
            EXPECT_NEAR(got, v, 1e-6) << i << " " << c;
            EXPECT_LE(std::abs(got - truth), (cmax[c] - cmin[c]) / 255 / 2 + 1e-6) << i;
        }
        // The engine's switch: mode 0 -> (w, x, y, z) = (d, a, b, c); 1 -> (a, d, b, c);
        // 2 -> (a, b, d, c); 3 -> (a, b, c, d).
        const uint8_t* qb = px("quats.webp", i);
        const double a = (qb[0] / 255.0 - 0.5) * kSqrt2, b = (qb[1] / 255.0 - 0.5) * kSqrt2,
                     c = (qb[2] / 255.0 - 0.5) * kSqrt2;
        const double d = std::sqrt(std::max(0.0, 1.0 - a * a - b * b - c * c));
        double q[4];
        switch (qb[3] - 252) {
            case 0:
                q[0] = d, q[1] = a, q[2] = b, q[3] = c;
                break;
            case 1:
                q[0] = a, q[1] = d, q[2] = b, q[3] = c;
                break;
            case 2:
                q[0] = a, q[1] = b, q[2] = d, q[3] = c;
                break;
            default:
                q[0] = a, q[1] = b, q[2] = c, q[3] = d;
                break;
        }
        const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        int largest = 0;
        for (int k = 1; k < 4; ++k)
            largest = std::abs(t.rot[i * 4 + k]) > std::abs(t.rot[i * 4 + largest]) ? k : largest;
        const double sign = t.rot[i * 4 + largest] < 0 ? -1.0 : 1.0;
        for (int k = 0; k < 4; ++k) {
            const double got = F(cloud, "rot")[i * 4 + k];
            EXPECT_NEAR(got, q[k] / norm, 1e-6) << i;
            worst_rot = std::max(worst_rot, std::abs(got - sign * t.rot[i * 4 + k]));
        }
        if (t.degree == 0) continue;
        const double emin = m["shN"]["mins"], emax = m["shN"]["maxs"];
        const uint8_t* lb = px("shN_labels.webp", i);
        const int label = lb[0] + 256 * lb[1];
        ASSERT_EQ(label, t.label[i]);
        const Rgba8Image& cent = sog.images.at("shN_centroids.webp");
        for (int j = 0; j < nc; ++j) {
            const uint8_t* texel =
                &cent.rgba[((label / 64) * cent.width + (label % 64) * nc + j) * 4];
            for (int ch = 0; ch < 3; ++ch) {
                const double got = F(cloud, "f_rest")[(i * nc + j) * 3 + ch];
                EXPECT_NEAR(got, Lerp(emin, emax, texel[ch] / 255.0), 1e-6) << i;
                EXPECT_LE(std::abs(got - t.entries[(label * nc + j) * 3 + ch]),
                          (emax - emin) / 255 / 2 + 1e-6)
                    << i;
            }
        }
    }
    EXPECT_LE(worst_rot, 0.0085);
}

TEST(SogV1Format, KnownSplatsWithinQuantisation) {
    const std::string dir = tests::TempDir();
    // 150 splats in 16 x 10 texels (10 of padding); palettes of 70 (2 rows, labels to 69),
    // 64 (1 row) and 300 entries (5 rows, labels above 255: the high byte counts).
    const int palettes[4] = {0, 70, 64, 300};
    for (int degree = 0; degree <= 3; ++degree) {
        SCOPED_TRACE("degree " + std::to_string(degree));
        const Truth t = RandomTruth(150, degree, palettes[degree], 11 + degree);
        const V1Sog sog = Encode(t, 16, 10);
        const std::string path = dir + "/deg" + std::to_string(degree) + ".sog";
        ExpectDecodes(Read(Write(sog, path)), sog, t);
    }
}

// The folder form, its meta.json, the bundled .sog and an explicit "version": 1 read alike.
TEST(SogV1Format, FolderMetaJsonAndVersionOne) {
    const std::string dir = tests::TempDir();
    const Truth t = RandomTruth(40, 2, 64, 5);
    V1Sog sog = Encode(t, 8, 5);
    const PointCloud bundled = Read(Write(sog, dir + "/v1.sog"));
    ExpectDecodes(bundled, sog, t);
    const std::string folder = Write(sog, dir + "/folder", /*zip=*/false);
    EXPECT_EQ(DetectPointCloudFileFormat(folder), PointCloudFileFormat::kSog);
    EXPECT_TRUE(Read(folder) == bundled);
    EXPECT_TRUE(Read(folder + "/meta.json") == bundled);
    sog.meta["version"] = 1;
    EXPECT_TRUE(Read(Write(sog, dir + "/explicit.sog")) == bundled);
}

TEST(SogV1Format, MalformedFilesFailCleanly) {
    const std::string dir = tests::TempDir();
    const V1Sog good = Encode(RandomTruth(30, 1, 70, 3), 6, 6);
    ASSERT_EQ(Read(Write(good, dir + "/good.sog")).NumPoints(), 30);
    int k = 0;
    const auto variant = [&](const std::function<void(V1Sog&)>& edit) {
        V1Sog sog = good;
        edit(sog);
        return Write(sog, dir + "/bad" + std::to_string(k++) + ".sog");
    };
    const auto meta = [&](const std::function<void(Json&)>& edit) {
        return variant([&](V1Sog& sog) { edit(sog.meta); });
    };
    // Without "version" the errors say the file was taken for version 1.
    ExpectError(meta([](Json& m) { m["means"].erase("shape"); }),
                {"meta.json (no 'version': SOG version 1)", "'means.shape' is missing"});
    ExpectError(meta([](Json& m) {
                    m["version"] = 1;
                    m["means"].erase("shape");
                }),
                {"meta.json (SOG version 1)", "'means.shape' is missing"});
    ExpectError(meta([](Json& m) { m["means"]["shape"] = Json::array(); }),
                {"'means.shape'", "[count, 3]"});
    ExpectError(meta([](Json& m) { m["means"]["shape"][0] = -1; }), {"'means.shape[0]'", "-1"});
    ExpectError(meta([](Json& m) { m["means"]["shape"][0] = 37; }),
                {"means_l.webp", "6x6 = 36 texels, fewer than count 37"});
    ExpectError(meta([](Json& m) {
                    m["scales"]["mins"] = {0.0, 0.0};
                }),
                {"'scales.mins'", "3 numbers"});
    ExpectError(meta([](Json& m) { m["sh0"]["mins"].erase(3); }), {"'sh0.mins'", "4 numbers"});
    ExpectError(meta([](Json& m) { m["sh0"].erase("maxs"); }), {"'sh0.maxs' is missing"});
    ExpectError(meta([](Json& m) { m["scales"]["mins"][1] = 1e300; }),
                {"'scales.mins[1]'", "overflows float"});
    ExpectError(meta([](Json& m) { m["shN"]["mins"] = Json::array({-1.0}); }),
                {"'shN.mins'", "expected a number"});
    ExpectError(meta([](Json& m) { m["shN"].erase("maxs"); }), {"'shN.maxs' is missing"});
    ExpectError(meta([](Json& m) { m["shN"]["quantization"] = 6; }), {"'shN.quantization'", "6"});
    ExpectError(meta([](Json& m) { m["quats"]["encoding"] = "quaternion_raw"; }),
                {"'quats.encoding'", "quaternion_raw"});
    ExpectError(meta([](Json& m) { m["means"]["files"] = Json::array({"means_l.webp"}); }),
                {"'means.files'", "2 file name"});
    ExpectError(meta([](Json& m) { m.erase("quats"); }), {"'quats' is missing"});
    ExpectError(meta([](Json& m) { m["version"] = 4; }), {"'version'", "4", "1, 2 and 3"});
    ExpectError(meta([](Json& m) {
                    m["opacities"] = {{"mins", {0.0}}, {"maxs", {1.0}}};
                }),
                {"'opacities'", "first SOGS layout"});
    // Images: missing, of another size, a palette of a width that gives no band count, a
    // label past the palette's rows, a quaternion alpha outside 252..255.
    ExpectError(variant([](V1Sog& s) { s.images.erase("sh0.webp"); }), {"sh0.webp"});
    ExpectError(variant([](V1Sog& s) { s.images["scales.webp"] = Blank(4, 9); }),
                {"scales.webp", "4x9", "must share one size"});
    ExpectError(variant([](V1Sog& s) { s.images["shN_centroids.webp"] = Blank(100, 2); }),
                {"shN_centroids.webp", "100 texels wide", "192"});
    ExpectError(variant([](V1Sog& s) { s.images["shN_labels.webp"].rgba[4 * 4 + 0] = 130; }),
                {"shN_labels.webp", "splat 4", "label 130", "2 rows"});
    ExpectError(variant([](V1Sog& s) { s.images["quats.webp"].rgba[3 * 4 + 3] = 17; }),
                {"quats.webp", "splat 3", "alpha 17"});
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
