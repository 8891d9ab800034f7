// glTF 2.0 KHR_gaussian_splatting: the reader against assets built byte by byte here (data-URI,
// external .bin, .glb; float and normalised-integer attributes; node transforms; sparse
// accessors), the early-draft Cesium fixture against an independent decode, the glTF <-> RDF
// axis change checked by evaluating the spec's own SH formula, writer round trips (synthetic,
// biker_152k, pc_short). Malformed input: GltfMalformedTest.cpp.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "GltfTestAssets.h"
#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/t/geometry/SHRotation.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/GltfCommon.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using namespace gltf_test;

// The spec's colour formula (README "Calculating color from Spherical Harmonics", constants
// and signs copied from its text, not from SphericalHarmonics.h); c[j], j = l^2 + l + m.
double SpecColour(const double* c, int degree, double x, double y, double z) {
    double v = c[0] * 0.2820947917738781;
    if (degree >= 1) {
        v += c[1] * y * -0.4886025119029199 + c[2] * z * 0.4886025119029199 +
             c[3] * x * -0.4886025119029199;
    }
    if (degree >= 2) {
        v += c[4] * x * y * 1.092548430592079 + c[5] * y * z * -1.092548430592079 +
             c[6] * (2 * z * z - x * x - y * y) * 0.3153915652525200 +
             c[7] * x * z * -1.092548430592079 + c[8] * (x * x - y * y) * 0.5462742152960395;
    }
    if (degree >= 3) {
        v += c[9] * y * (3 * x * x - y * y) * -0.5900435899266435 +
             c[10] * x * y * z * 2.890611442640554 +
             c[11] * y * (4 * z * z - x * x - y * y) * -0.4570457994644657 +
             c[12] * z * (2 * z * z - 3 * x * x - 3 * y * y) * 0.3731763325901154 +
             c[13] * x * (4 * z * z - x * x - y * y) * -0.4570457994644657 +
             c[14] * z * (x * x - y * y) * 1.445305721320277 +
             c[15] * x * (x * x - 3 * y * y) * -0.5900435899266435;
    }
    return v + 0.5;
}

Eigen::Vector3d RandomDirection(std::mt19937& rng) {
    std::normal_distribution<double> normal;
    return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
}

// Colour of splat i of a cloud (RDF) towards direction d (RDF), channel ch, as the renderer
// evaluates it.
double CloudColour(const PointCloud& cloud, int64_t i, const Eigen::Vector3d& d, int ch) {
    const int degree = cloud.GaussianSplatGetSHOrder();
    const int nc = geometry::NumSHRestCoeffs(degree);
    const float* rest =
        degree > 0 ? cloud.GetPointAttr("f_rest").Data<float>() + i * nc * 3 : nullptr;
    return geometry::EvaluateSH<double>(degree, cloud.GetPointAttr("f_dc").Data<float>() + i * 3,
                                        rest, d.x(), d.y(), d.z())[ch] +
           0.5;
}

// A random splat cloud (unit quaternions, positive scales, logits ~ 3 N(0, 1)).
PointCloud RandomCloud(int64_t n, int degree, uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> normal(0.0f, 1.0f);
    std::uniform_real_distribution<float> log_scale(-9.0f, 3.0f);
    const auto fill = [&](const core::SizeVector& shape, auto gen) {
        Tensor t(shape, core::Dtype::Float32);
        for (int64_t k = 0; k < t.NumElements(); ++k) t.Data<float>()[k] = gen();
        return t;
    };
    PointCloud cloud(fill({n, 3}, [&] { return 10.0f * normal(rng); }));
    cloud.SetPointAttr("scale", fill({n, 3}, [&] { return std::exp(log_scale(rng)); }));
    Tensor rot({n, 4}, core::Dtype::Float32);
    for (int64_t i = 0; i < n; ++i) {
        double q[4], norm = 0;
        for (double& v : q) {
            v = normal(rng);
            norm += v * v;
        }
        for (int k = 0; k < 4; ++k) rot.Data<float>()[i * 4 + k] = float(q[k] / std::sqrt(norm));
    }
    cloud.SetPointAttr("rot", rot);
    cloud.SetPointAttr("opacity", fill({n, 1}, [&] { return 3.0f * normal(rng); }));
    cloud.SetPointAttr("f_dc", fill({n, 3}, [&] { return normal(rng); }));
    if (degree > 0) {
        cloud.SetPointAttr("f_rest", fill({n, geometry::NumSHRestCoeffs(degree), 3},
                                          [&] { return 0.2f * normal(rng); }));
    }
    return cloud;
}

double Sigmoid(double x) { return 1.0 / (1.0 + std::exp(-x)); }

// Written -> read: every float attribute bit for bit; opacity (a linear alpha in the file) to
// float rounding of the alpha. Returns how many logits came back exactly.
int64_t ExpectSameCloud(const PointCloud& original, const PointCloud& back) {
    EXPECT_EQ(back.NumPoints(), original.NumPoints());
    EXPECT_EQ(back.GaussianSplatGetSHOrder(), original.GaussianSplatGetSHOrder());
    for (const char* name : {"positions", "scale", "rot", "f_dc"}) {
        EXPECT_TRUE(back.GetPointAttr(name) == original.GetPointAttr(name)) << name;
    }
    if (original.GaussianSplatGetSHOrder() > 0) {
        EXPECT_TRUE(back.GetPointAttr("f_rest") == original.GetPointAttr("f_rest"));
    }
    const float* o0 = original.GetPointAttr("opacity").Data<float>();
    const float* o1 = back.GetPointAttr("opacity").Data<float>();
    int64_t exact = 0;
    double worst = 0;
    for (int64_t i = 0; i < original.NumPoints(); ++i) {
        exact += o0[i] == o1[i];
        worst = std::max(worst, std::abs(Sigmoid(o0[i]) - Sigmoid(o1[i])));
    }
    // The alpha is rounded once to float (half an ulp, <= 2^-25 below 1) and the read logit
    // once more (moving the alpha by at most another 2^-25): 2^-24 = 6.0e-8.
    EXPECT_LE(worst, 0x1p-24);
    return exact;
}

TEST(GltfFormat, AxisChangeSignsFollowFromTheSpecBasis) {
    // glTF (x right, y up, z towards the viewer) -> RDF is the 180 degree turn about x,
    // C = diag(1, -1, -1). Converted coefficients must give the same colour towards C d as the
    // glTF ones towards d, with the colour formula of the spec's text.
    const Eigen::Matrix3d C = Eigen::Vector3d(1, -1, -1).asDiagonal();
    std::mt19937 rng(7);
    std::normal_distribution<double> normal;
    for (int trial = 0; trial < 200; ++trial) {
        double coef[16];
        float dc[3] = {}, rest[15 * 3] = {};
        for (int j = 0; j < 16; ++j) coef[j] = normal(rng);
        dc[0] = float(coef[0]);
        for (int j = 1; j < 16; ++j) {
            coef[j] = float(coef[j]);
            rest[(j - 1) * 3] = float(coef[j]) * gltf::kShSignRdf[j - 1];
        }
        coef[0] = dc[0];
        const Eigen::Vector3d d = RandomDirection(rng);
        const Eigen::Vector3d e = C * d;
        const double ours = geometry::EvaluateSH<double>(3, dc, rest, e.x(), e.y(), e.z())[0] + 0.5;
        EXPECT_NEAR(ours, SpecColour(coef, 3, d.x(), d.y(), d.z()), 1e-12);
    }
    // Every sign matters: flipping one changes the colour along some direction.
    for (int k = 0; k < 15; ++k) {
        double coef[16] = {};
        coef[k + 1] = 1;
        float dc[3] = {}, rest[15 * 3] = {};
        rest[k * 3] = -gltf::kShSignRdf[k];  // the wrong sign
        double worst = 0;
        for (int trial = 0; trial < 50; ++trial) {
            const Eigen::Vector3d d = RandomDirection(rng), e = C * d;
            worst = std::max(
                worst, std::abs(geometry::EvaluateSH<double>(3, dc, rest, e.x(), e.y(), e.z())[0] +
                                0.5 - SpecColour(coef, 3, d.x(), d.y(), d.z())));
        }
        EXPECT_GT(worst, 0.1) << "coefficient " << k;
    }
    // The same signs are the band matrices of C in SHRotation (a second derivation).
    const geometry::SHRotation rotation(C, 3);
    for (int l = 1; l <= 3; ++l) {
        const Eigen::MatrixXd band = rotation.GetBand(l);
        for (int a = 0; a < 2 * l + 1; ++a) {
            for (int b = 0; b < 2 * l + 1; ++b) {
                const double expected = a == b ? gltf::kShSignRdf[l * l - 1 + a] : 0.0;
                EXPECT_NEAR(band(a, b), expected, 1e-12) << "l " << l << " " << a << "," << b;
            }
        }
    }
}

TEST(GltfFormat, OpacityEncoding) {
    EXPECT_EQ(gltf::EncodeOpacity(gltf::kOpaqueLogit), 1.0f);
    EXPECT_EQ(gltf::EncodeOpacity(gltf::kTransparentLogit), 0.0f);
    EXPECT_EQ(gltf::DecodeOpacity(1.0f), gltf::kOpaqueLogit);
    EXPECT_EQ(gltf::DecodeOpacity(0.0f), gltf::kTransparentLogit);
    // Logits in [-87, -2] come back exactly (measured: 100% of 200k samples): there the alpha
    // (about e^logit, a normal float) is finer than the logit. Elsewhere it is not: near 0 the
    // logit's floats are denser than the alpha's, above 0 the alpha's spacing near 1 is too
    // coarse, below -87.3 the alpha is subnormal. Measured exact share: [-1, -0.5) 43%,
    // [0, 0.5) 8%, [1, 2) 30%, [4, 8) 4%, [16, 30) 0%; the alpha itself is always exact.
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> negative(-87.0f, -2.0f);
    int64_t exact = 0;
    for (int i = 0; i < 200000; ++i) {
        const float logit = negative(rng);
        exact += gltf::DecodeOpacity(gltf::EncodeOpacity(logit)) == logit;
    }
    EXPECT_EQ(exact, 200000);
    // Encode -> decode -> encode gives the same alpha (write -> read -> write is identical).
    std::uniform_real_distribution<float> any(-120.0f, 30.0f);
    for (int i = 0; i < 200000; ++i) {
        const float alpha = gltf::EncodeOpacity(any(rng));
        ASSERT_EQ(gltf::EncodeOpacity(gltf::DecodeOpacity(alpha)), alpha) << alpha;
    }
}

TEST(GltfFormat, ReadsDataUriExternalBinAndGlb) {
    const std::string dir = tests::TempDir();
    const Asset asset = MinimalAsset();
    for (const std::string& path : {asset.WriteGltf(dir + "/data_uri.gltf"),
                                    asset.WriteGltf(dir + "/external.gltf", "my%20splats.bin"),
                                    asset.WriteGlb(dir + "/minimal.glb")}) {
        SCOPED_TRACE(path);
        PointCloud cloud;
        const ReadPointCloudReport report = ReadPointCloud(path, cloud);
        EXPECT_EQ(report.num_points, 3);
        ExpectMinimalValues(cloud);
    }
    EXPECT_TRUE(fs::exists(dir + "/my splats.bin"));
}

// Normalised and unnormalised integers, byteStride, a sparse accessor without bufferView, SH
// degree 1, and a two-level node hierarchy (translation; rotation 90 degrees about y with
// scale 2), in a .glb.
TEST(GltfFormat, ReadsQuantisedGlbWithNodeTransform) {
    Asset a;
    a.json = Skeleton();
    a.json["nodes"] = {
        {{"translation", {1, 2, 3}}, {"children", {1}}},
        {{"rotation", {0, std::sqrt(0.5), 0, std::sqrt(0.5)}}, {"scale", {2, 2, 2}}, {"mesh", 0}}};
    Json& at = a.Attributes();
    // POSITION: float VEC3 padded to a 16-byte stride.
    const std::vector<float> pos = {1, 0, 0, 99, 0, 1, 0, 99, 0, 0, 1, 99};
    at["POSITION"] = a.Add(Raw(pos), kFloat, "VEC3", 3, false, 16);
    // ROTATION: signed short normalised, x y z w.
    const std::vector<int16_t> rot = {0, 0, 0, 32767, 32767, 0, 0, 0, 0, -32768, 0, 32767};
    at[kP + "ROTATION"] = a.Add(Raw(rot), kShort, "VEC4", 3, true);
    // SCALE: unsigned byte, not normalised, 4-byte stride.
    const std::vector<uint8_t> scale = {1, 2, 3, 0, 4, 5, 6, 0, 7, 8, 9, 0};
    at[kP + "SCALE"] = a.Add(scale, kUByte, "VEC3", 3, false, 4);
    // OPACITY: unsigned byte normalised.
    at[kP + "OPACITY"] =
        a.Add({255, 0, 0, 0, 0, 0, 0, 0, 51, 0, 0, 0}, kUByte, "SCALAR", 3, true, 4);
    // SH degree 0: zeros but splat 1, by a sparse accessor with no bufferView.
    const int dc = a.AddAccessor(-1, 0, kFloat, "VEC3", 3);
    a.json["accessors"][dc]["sparse"] = {
        {"count", 1},
        {"indices", {{"bufferView", a.AddView({1, 0, 0, 0})}, {"componentType", kUByte}}},
        {"values", {{"bufferView", a.AddView(Raw(std::vector<float>{0.25f, 0.5f, 0.75f}))}}}};
    at[kP + "SH_DEGREE_0_COEF_0"] = dc;
    double sh1[3][3][3];  // [n][splat][channel], glTF frame
    for (int n = 0; n < 3; ++n) {
        std::vector<float> v;
        for (int i = 0; i < 3; ++i) {
            for (int c = 0; c < 3; ++c) v.push_back(float(0.1 * (n + 1) - 0.05 * i + 0.01 * c));
        }
        at[kP + "SH_DEGREE_1_COEF_" + std::to_string(n)] = a.Add(Raw(v), kFloat, "VEC3", 3);
        for (int i = 0; i < 3; ++i) {
            for (int c = 0; c < 3; ++c) sh1[n][i][c] = v[i * 3 + c];
        }
    }
    const std::string path = a.WriteGlb(tests::TempDir() + "/quantised.glb");
    PointCloud cloud;
    ReadPointCloud(path, cloud);
    ASSERT_EQ(cloud.NumPoints(), 3);
    ASSERT_EQ(cloud.GaussianSplatGetSHOrder(), 1);

    // World (glTF) = T(1,2,3) * R_y(90) * 2; RDF = C * world. R_y(90): (x, y, z) -> (z, y, -x).
    const Eigen::Matrix3d C = Eigen::Vector3d(1, -1, -1).asDiagonal();
    const Eigen::Matrix3d Ry =
        Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const float expected_pos[3][3] = {{1, -2, -1}, {1, -4, -3}, {3, -2, -3}};
    const float* p = cloud.GetPointPositions().Data<float>();
    const float* s = cloud.GetPointAttr("scale").Data<float>();
    const float* q = cloud.GetPointAttr("rot").Data<float>();
    const float* o = cloud.GetPointAttr("opacity").Data<float>();
    const float* f_dc = cloud.GetPointAttr("f_dc").Data<float>();
    for (int i = 0; i < 3; ++i) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(p[i * 3 + c], expected_pos[i][c], 1e-6) << i;
            EXPECT_EQ(s[i * 3 + c], 2.0f * scale[i * 4 + c]);
            EXPECT_EQ(f_dc[i * 3 + c], i == 1 ? 0.25f * (c + 1) : 0.0f);
        }
        // Rotation matrices: read = C * R_y * R(file quaternion, normalised).
        const double file[4] = {std::max(rot[i * 4] / 32767.0, -1.0),
                                std::max(rot[i * 4 + 1] / 32767.0, -1.0),
                                std::max(rot[i * 4 + 2] / 32767.0, -1.0), rot[i * 4 + 3] / 32767.0};
        const Eigen::Matrix3d r_file =
            Eigen::Quaterniond(file[3], file[0], file[1], file[2]).normalized().toRotationMatrix();
        const Eigen::Matrix3d r_read =
            Eigen::Quaterniond(q[i * 4], q[i * 4 + 1], q[i * 4 + 2], q[i * 4 + 3])
                .toRotationMatrix();
        EXPECT_LT((r_read - C * Ry * r_file).cwiseAbs().maxCoeff(), 1e-6) << i;
        // SH: the colour towards C R_y d equals the file's colour towards d (spec formula).
        std::mt19937 rng(i);
        for (int trial = 0; trial < 20; ++trial) {
            const Eigen::Vector3d d = RandomDirection(rng);
            for (int c = 0; c < 3; ++c) {
                const double coef[4] = {f_dc[i * 3 + c], sh1[0][i][c], sh1[1][i][c], sh1[2][i][c]};
                EXPECT_NEAR(CloudColour(cloud, i, C * Ry * d, c),
                            SpecColour(coef, 1, d.x(), d.y(), d.z()), 1e-6);
            }
        }
    }
    EXPECT_EQ(o[0], gltf::kOpaqueLogit);
    EXPECT_EQ(o[1], gltf::kTransparentLogit);
    EXPECT_FLOAT_EQ(o[2], float(std::log(0.2 / 0.8)));
}

// A node with a non-uniform scale (the spec's "decomposable" transforms include it): the
// covariance is M Sigma M^T (then C), the SH follow the rotation part of M only.
TEST(GltfFormat, NonUniformNodeScaleKeepsCovarianceAndTurnsSh) {
    Asset a = MinimalAsset();
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 2, 2).normalized()));
    a.json["nodes"][0]["rotation"] = {turn.x(), turn.y(), turn.z(), turn.w()};
    a.json["nodes"][0]["scale"] = {1.0, 2.5, 0.5};
    a.json["nodes"][0]["translation"] = {-1.0, 0.0, 3.0};
    PointCloud cloud;
    ReadPointCloud(a.WriteGltf(tests::TempDir() + "/stretched.gltf"), cloud);
    ASSERT_EQ(cloud.NumPoints(), 3);
    const Eigen::Matrix3d C = Eigen::Vector3d(1, -1, -1).asDiagonal();
    const Eigen::Matrix3d R = turn.toRotationMatrix();
    const Eigen::Matrix3d M = R * Eigen::Vector3d(1.0, 2.5, 0.5).asDiagonal();
    const float* p = cloud.GetPointPositions().Data<float>();
    const float* q = cloud.GetPointAttr("rot").Data<float>();
    const float* s = cloud.GetPointAttr("scale").Data<float>();
    std::mt19937 rng(3);
    for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d x =
            C * (M * Eigen::Vector3d(kPos[i * 3], kPos[i * 3 + 1], kPos[i * 3 + 2]) +
                 Eigen::Vector3d(-1, 0, 3));
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(p[i * 3 + c], x[c], 1e-5) << i;
        const Eigen::Matrix3d r_file = Eigen::Quaterniond(kRotXyzw[i * 4 + 3], kRotXyzw[i * 4],
                                                          kRotXyzw[i * 4 + 1], kRotXyzw[i * 4 + 2])
                                           .toRotationMatrix();
        const Eigen::Matrix3d a_file =
            C * M * r_file *
            Eigen::Vector3d(kScale[i * 3], kScale[i * 3 + 1], kScale[i * 3 + 2]).asDiagonal();
        const Eigen::Matrix3d a_read =
            Eigen::Quaterniond(q[i * 4], q[i * 4 + 1], q[i * 4 + 2], q[i * 4 + 3])
                .toRotationMatrix() *
            Eigen::Vector3d(s[i * 3], s[i * 3 + 1], s[i * 3 + 2]).asDiagonal();
        const Eigen::Matrix3d sigma_file = a_file * a_file.transpose();
        const Eigen::Matrix3d sigma_read = a_read * a_read.transpose();
        const double error =
            (sigma_read - sigma_file).cwiseAbs().maxCoeff() / sigma_file.cwiseAbs().maxCoeff();
        // float32 quaternion and scales: measured 4.8e-8, 6.8e-8, 1.1e-7.
        EXPECT_LT(error, 1e-6) << i;
        for (int trial = 0; trial < 10; ++trial) {
            const Eigen::Vector3d d = RandomDirection(rng);
            for (int c = 0; c < 3; ++c) {
                const double coef[4] = {kDc[i * 3 + c], Sh1(0, i, c), Sh1(1, i, c), Sh1(2, i, c)};
                EXPECT_NEAR(CloudColour(cloud, i, C * R * d, c),
                            SpecColour(coef, 1, d.x(), d.y(), d.z()), 1e-6);
            }
        }
    }
}

// The early-draft Cesium tile (formats/README.md): POSITION, COLOR_0 (ubyte normalised, alpha =
// opacity), _SCALE (linear), _ROTATION (x y z w), empty extension object; its node matrix turns
// +90 degrees about x and translates. Expected values decoded independently:
//
//   import base64, json, math, struct
//   d = json.load(open('cesium_synthetic_0.gltf'))
//   buf = base64.b64decode(d['buffers'][0]['uri'].split(',', 1)[1])
//   f32 = lambda v: struct.unpack('<f', struct.pack('<f', v))[0]
//   def acc(name):
//       a = d['accessors'][d['meshes'][0]['primitives'][0]['attributes'][name]]
//       v = d['bufferViews'][a['bufferView']]
//       n = {'VEC3': 3, 'VEC4': 4}[a['type']]
//       fmt = {5126: 'f', 5121: 'B'}[a['componentType']]
//       off = v.get('byteOffset', 0) + a.get('byteOffset', 0)
//       return [struct.unpack_from('<%d%s' % (n, fmt), buf, off + i * n * struct.calcsize(fmt))
//               for i in range(a['count'])]
//   m = d['nodes'][0]['matrix']                  # column-major
//   M = [[m[c * 4 + r] for c in range(3)] for r in range(3)]
//   t = m[12:15]
//   C = [1, -1, -1]                              # glTF -> RDF: 180 degrees about x
//   L = [[C[r] * M[r][c] for c in range(3)] for r in range(3)]
//   h = math.sqrt(0.5)                           # L is +90 degrees about x: q_L = (h, h, 0, 0)
//   for p, s, (x, y, z, w), rgba in zip(acc('POSITION'), acc('_SCALE'), acc('_ROTATION'),
//                                        acc('COLOR_0')):
//       pos = [f32(sum(L[r][c] * p[c] for c in range(3)) + C[r] * t[r]) for r in range(3)]
//       q = (h * w - h * x, h * x + h * w, h * y - h * z, h * z + h * y)   # q_L * q
//       n = math.sqrt(sum(v * v for v in q))
//       rot = [f32(v / n) for v in q]
//       dc = [f32((f32(c / 255) - 0.5) / 0.28209479177387814) for c in rgba[:3]]
//       a = f32(rgba[3] / 255)
//       print(pos, rot, [f32(v) for v in s], f32(math.log(a / (1 - a))), dc)
TEST(GltfFormat, ReadsEarlyDraftCesiumFixture) {
    OPEN3D_REQUIRE_DATA("formats/cesium_synthetic_0.gltf");
    struct Splat {
        float pos[3], rot[4], scale[3], opacity, dc[3];
    };
    const Splat expected[5] = {
        {{4.4408921e-16f, -10, 5},
         {0.707106769f, 0.707106769f, 0, 0},
         {2.71828175f, 2.71828175f, 2.71828175f},
         0.196710408f,
         {-0.00695079891f, 0.993964374f, 1.7724539f}},
        {{1, -11, 6},
         {0.596039534f, 0.728492796f, -0.0662266165f, 0.331133097f},
         {3.00416613f, 3.00416613f, 3.00416613f},
         0.389151633f,
         {0.0903604925f, 1.09127557f, 1.7724539f}},
        {{2, -12, 7},
         {0.452910811f, 0.679366231f, -0.113227695f, 0.566138506f},
         {3.320117f, 3.320117f, 3.320117f},
         0.58900702f,
         {0.187671676f, 1.18858671f, 1.7724539f}},
        {{3, -13, 8},
         {0.329252303f, 0.611468554f, -0.141108111f, 0.705540657f},
         {3.6692965f, 3.6692965f, 3.6692965f},
         0.782759428f,
         {0.298884451f, 1.29979956f, 1.7724539f}},
        {{4, -14, 9},
         {0.235702261f, 0.549971938f, -0.157134846f, 0.785674214f},
         {4.0552001f, 4.0552001f, 4.0552001f},
         0.99164027f,
         {0.39619565f, 1.3971107f, 1.7724539f}},
    };
    int draft_warnings = 0;
    auto previous = core::SetLogSink([&](core::LogLevel level, std::string_view msg) {
        if (level == core::LogLevel::Warning && msg.find("early draft") != msg.npos)
            ++draft_warnings;
    });
    PointCloud cloud;
    const ReadPointCloudReport report =
        ReadPointCloud(tests::DataPath("formats/cesium_synthetic_0.gltf"), cloud);
    core::SetLogSink(previous);
    EXPECT_EQ(draft_warnings, 1);
    ASSERT_EQ(report.num_points, 5);
    ASSERT_EQ(cloud.GaussianSplatGetSHOrder(), 0);
    const float* p = cloud.GetPointPositions().Data<float>();
    const float* q = cloud.GetPointAttr("rot").Data<float>();
    const float* s = cloud.GetPointAttr("scale").Data<float>();
    const float* o = cloud.GetPointAttr("opacity").Data<float>();
    const float* dc = cloud.GetPointAttr("f_dc").Data<float>();
    for (int i = 0; i < 5; ++i) {
        const Splat& e = expected[i];
        const float sign = q[i * 4] < 0 ? -1.0f : 1.0f;  // q and -q are the same rotation
        for (int c = 0; c < 3; ++c) {
            // One rounding of a double sum whose terms are exact (matrix entries 0 and +-1).
            EXPECT_EQ(p[i * 3 + c], e.pos[c]) << i;
            EXPECT_EQ(s[i * 3 + c], e.scale[c]) << i;  // float, unchanged by a rigid node
            EXPECT_NEAR(dc[i * 3 + c], e.dc[c], 1e-6) << i;
        }
        for (int c = 0; c < 4; ++c) EXPECT_NEAR(sign * q[i * 4 + c], e.rot[c], 2e-7) << i;
        EXPECT_NEAR(o[i], e.opacity, 1e-6) << i;
    }
}

TEST(GltfFormat, WriterRoundTripsExactlyAndIsIdempotent) {
    const std::string dir = tests::TempDir();
    for (int degree = 0; degree <= 3; ++degree) {
        SCOPED_TRACE(degree);
        const PointCloud original = RandomCloud(300, degree, 40 + degree);
        const std::string glb = dir + "/d" + std::to_string(degree) + ".glb";
        const std::string gltf = dir + "/d" + std::to_string(degree) + ".gltf";
        WritePointCloud(glb, original);
        WritePointCloud(gltf, original);
        PointCloud from_glb, from_gltf;
        ReadPointCloud(glb, from_glb);
        ReadPointCloud(gltf, from_gltf);
        ExpectSameCloud(original, from_glb);
        EXPECT_TRUE(from_gltf == from_glb);
        // write -> read -> write: byte-identical.
        WritePointCloud(dir + "/again.glb", from_glb);
        EXPECT_EQ(ReadBytes(dir + "/again.glb"), ReadBytes(glb));
        WritePointCloud(dir + "/again.gltf", from_gltf);
        EXPECT_EQ(ReadBytes(dir + "/again.gltf"), ReadBytes(gltf));

        // The file itself, decoded here with the spec's rules: GLB header and chunks, current
        // attribute names, float accessors, colours in glTF axes equal to the cloud's in RDF.
        const std::vector<uint8_t> bytes = ReadBytes(glb);
        uint32_t header[5];
        std::memcpy(header, bytes.data(), sizeof(header));
        EXPECT_EQ(header[0], 0x46546C67u);
        EXPECT_EQ(header[1], 2u);
        EXPECT_EQ(header[2], bytes.size());
        EXPECT_EQ(header[3] % 4, 0u);
        EXPECT_EQ(header[4], 0x4E4F534Au);
        const Json j = Json::parse(bytes.begin() + 20, bytes.begin() + 20 + header[3]);
        const uint8_t* bin = bytes.data() + 20 + header[3] + 8;
        const Json& prim = j["meshes"][0]["primitives"][0];
        EXPECT_EQ(prim["mode"], 0);
        EXPECT_EQ(prim["extensions"]["KHR_gaussian_splatting"]["kernel"], "ellipse");
        EXPECT_EQ(prim["extensions"]["KHR_gaussian_splatting"]["colorSpace"],
                  "srgb_rec709_display");
        EXPECT_TRUE(j["accessors"][0].contains("min") && j["accessors"][0].contains("max"));
        const auto attribute = [&](const std::string& name, int64_t i, int c) {
            const Json& acc = j["accessors"][prim["attributes"][name].get<int>()];
            EXPECT_EQ(acc["componentType"], kFloat);
            const Json& view = j["bufferViews"][acc["bufferView"].get<int>()];
            const int width = acc["type"] == "VEC4" ? 4 : acc["type"] == "VEC3" ? 3 : 1;
            float v;
            std::memcpy(&v, bin + view["byteOffset"].get<size_t>() + (i * width + c) * 4, 4);
            return double(v);
        };
        const Eigen::Matrix3d C = Eigen::Vector3d(1, -1, -1).asDiagonal();
        std::mt19937 rng(degree);
        for (int64_t i = 0; i < 300; i += 37) {
            EXPECT_EQ(attribute("POSITION", i, 1),
                      -original.GetPointPositions().Data<float>()[i * 3 + 1]);
            EXPECT_NEAR(attribute(kP + "OPACITY", i, 0),
                        Sigmoid(original.GetPointAttr("opacity").Data<float>()[i]), 6e-8);
            for (int c = 0; c < 3; ++c) {
                double coef[16];
                for (int l = 0; l <= degree; ++l) {
                    for (int n = 0; n < 2 * l + 1; ++n) {
                        coef[l * l + n] = attribute(
                            kP + "SH_DEGREE_" + std::to_string(l) + "_COEF_" + std::to_string(n), i,
                            c);
                    }
                }
                const Eigen::Vector3d d = RandomDirection(rng);
                EXPECT_NEAR(SpecColour(coef, degree, d.x(), d.y(), d.z()),
                            CloudColour(original, i, C * d, c), 1e-6);
            }
        }
    }
}

// 3DGS PLY -> .glb -> reader: float32 positions, scales (linear in both), rotations, f_dc and
// f_rest bit-exact; opacity (a linear alpha in glTF) to float rounding of the alpha.
void PlyRoundTrip(const std::string& relative, int expected_degree) {
    PointCloud ply;
    ReadPointCloud(tests::DataPath(relative), ply);
    ASSERT_EQ(ply.GaussianSplatGetSHOrder(), expected_degree);
    const std::string dir = tests::TempDir();
    WritePointCloud(dir + "/a.glb", ply);
    PointCloud back;
    ReadPointCloud(dir + "/a.glb", back);
    const int64_t exact = ExpectSameCloud(ply, back);
    std::printf("%s: %lld splats, %lld opacity logits exact (%.2f%%)\n", relative.c_str(),
                (long long)ply.NumPoints(), (long long)exact, 100.0 * exact / ply.NumPoints());
    WritePointCloud(dir + "/b.glb", back);
    EXPECT_EQ(ReadBytes(dir + "/a.glb"), ReadBytes(dir + "/b.glb"));
}

TEST(GltfFormat, PlyRoundTripBiker) {
    OPEN3D_REQUIRE_DATA("biker/biker_152k.ply");
    PlyRoundTrip("biker/biker_152k.ply", 0);
}

TEST(GltfFormat, PlyRoundTripPcShortDegree3) {
    OPEN3D_REQUIRE_DATA("pc_short/pc_short.ply");
    PlyRoundTrip("pc_short/pc_short.ply", 3);
}

TEST(GltfFormat, WriterRefusesWhatGltfCannotHold) {
    const std::string dir = tests::TempDir();
    PointCloud negative = RandomCloud(2, 0, 1);
    negative.GetPointAttr("scale").Data<float>()[4] = -1.0f;
    EXPECT_THROW(WritePointCloud(dir + "/neg.glb", negative), Open3DError);
    PointCloud nan = RandomCloud(2, 0, 1);
    nan.GetPointAttr("positions").Data<float>()[0] = NAN;
    EXPECT_THROW(WritePointCloud(dir + "/nan.glb", nan), Open3DError);
    EXPECT_THROW(WritePointCloud(dir + "/plain.glb",
                                 PointCloud(Tensor::FromVector<float>({1, 2, 3, 4, 5, 6}, {2, 3}))),
                 Open3DError);
}

// The fuzz seeds (tests/fuzz/seeds/*.gltf, *.glb) stay valid splat files of this reader.
TEST(GltfFormat, FuzzSeedsAreValid) {
    int seeds = 0;
    for (const auto& entry :
         fs::directory_iterator(std::string(OPEN3D_TEST_SOURCE_DIR) + "/fuzz/seeds")) {
        const std::string ext = entry.path().extension().string();
        if (ext != ".gltf" && ext != ".glb") continue;
        PointCloud cloud;
        EXPECT_NO_THROW(ReadPointCloud(entry.path().string(), cloud)) << entry.path();
        EXPECT_GT(cloud.NumPoints(), 0) << entry.path();
        ++seeds;
    }
    EXPECT_GE(seeds, 3);
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
