// glTF primitives compressed with the draft KHR_spz_gaussian_splats_compression (GltfSpz.cpp):
// the SPZ bytes come from this library's SPZ writer, the glTF around them is built here as the
// draft shows it, and the cloud read from the glTF is checked against the cloud read from the
// .spz file itself.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>

#include "GltfTestAssets.h"
#include "RandomSplatCloud.h"
#include "TestUtility.h"
#include "open3d/core/Logging.h"
#include "open3d/t/geometry/SphericalHarmonics.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using namespace gltf_test;

const std::string kSpz = "KHR_spz_gaussian_splats_compression";

// The SPZ file this library writes for `cloud`, and its bytes.
std::vector<uint8_t> SpzBytes(const PointCloud& cloud, const std::string& path) {
    WritePointCloud(path, cloud);
    return ReadBytes(path);
}

// The draft's asset (CesiumGS/glTF draft-spz-splat-compression README, as in SharpGLTF's
// tower.glb): the SPZ in bufferView 0, accessors without a bufferView for POSITION, COLOR_0,
// _SCALE, _ROTATION and the SH coefficients of `degree`, one node, the extension required.
Asset SpzAsset(const std::vector<uint8_t>& spz, int n, int degree) {
    Asset a;
    a.json = {{"asset", {{"version", "2.0"}}}, {"extensionsUsed", {kSpz}},
              {"extensionsRequired", {kSpz}},  {"scene", 0},
              {"scenes", {{{"nodes", {0}}}}},  {"nodes", {{{"mesh", 0}}}},
              {"accessors", Json::array()},    {"bufferViews", Json::array()}};
    const int view = a.AddView(spz);
    Json attributes;
    attributes["POSITION"] = a.AddAccessor(-1, 0, kFloat, "VEC3", n);
    attributes["COLOR_0"] = a.AddAccessor(-1, 0, kUByte, "VEC4", n, true);
    attributes["_SCALE"] = a.AddAccessor(-1, 0, kFloat, "VEC3", n);
    attributes["_ROTATION"] = a.AddAccessor(-1, 0, kFloat, "VEC4", n);
    for (int l = 1; l <= degree; ++l) {
        for (int m = 0; m < 2 * l + 1; ++m) {
            attributes["_SH_DEGREE_" + std::to_string(l) + "_COEF_" + std::to_string(m)] =
                a.AddAccessor(-1, 0, kFloat, "VEC3", n);
        }
    }
    a.json["meshes"] = {{{"primitives",
                          {{{"attributes", attributes},
                            {"mode", 0},
                            {"extensions", {{kSpz, {{"bufferView", view}}}}}}}}}};
    return a;
}

// Every attribute bit for bit.
void ExpectSameCloud(const PointCloud& read, const PointCloud& expected) {
    ASSERT_EQ(read.NumPoints(), expected.NumPoints());
    ASSERT_EQ(read.GaussianSplatGetSHOrder(), expected.GaussianSplatGetSHOrder());
    for (const char* name : {"positions", "scale", "rot", "opacity", "f_dc", "f_rest"}) {
        if (!expected.HasPointAttr(name)) continue;
        const Tensor a = read.GetPointAttr(name), b = expected.GetPointAttr(name);
        ASSERT_EQ(a.GetShape(), b.GetShape()) << name;
        const float* x = a.Data<float>();
        const float* y = b.Data<float>();
        int64_t differ = 0;
        for (int64_t k = 0; k < a.NumElements(); ++k) differ += x[k] != y[k];
        EXPECT_EQ(differ, 0) << name;
    }
}

// Without a node transform the glTF cloud is the .spz cloud exactly: the SPZ values are the
// primitive's glTF coordinates, as stored (CesiumJS's reading, GltfSpz.cpp), and glTF -> RDF
// is the same sign flip (x, -y, -z) as SPZ's RUB -> RDF, so no value is rounded differently.
TEST(GltfSpz, GlbAndGltfEqualTheSpzFile) {
    const std::string dir = tests::TempDir();
    for (int degree : {0, 3}) {
        const PointCloud cloud = RandomCloud(200, degree, 11 + degree);
        const std::string spz_path = dir + "/spz_" + std::to_string(degree) + ".spz";
        const Asset a = SpzAsset(SpzBytes(cloud, spz_path), 200, degree);
        PointCloud from_spz, from_glb, from_gltf;
        ReadPointCloud(spz_path, from_spz);
        ReadPointCloud(a.WriteGlb(dir + "/spz_" + std::to_string(degree) + ".glb"), from_glb);
        ReadPointCloud(a.WriteGltf(dir + "/spz_" + std::to_string(degree) + ".gltf"), from_gltf);
        ExpectSameCloud(from_glb, from_spz);
        ExpectSameCloud(from_gltf, from_spz);
        // Not merely the same decode twice: the positions are SPZ's 12-bit fixed point.
        const float x = from_glb.GetPointPositions().Data<float>()[0];
        EXPECT_EQ(x * 4096.0f, std::round(x * 4096.0f));
    }
}

// The revision (CesiumGS/glTF pull 86) puts an empty KHR_gaussian_splatting beside the SPZ
// extension; CesiumJS also takes the KHR_gaussian_splatting: attribute names. Both at once are
// valid: the SPZ supplies the values.
TEST(GltfSpz, BesideKhrGaussianSplatting) {
    const std::string dir = tests::TempDir();
    const PointCloud cloud = RandomCloud(50, 1, 5);
    Asset a = SpzAsset(SpzBytes(cloud, dir + "/beside.spz"), 50, 1);
    a.json["extensionsUsed"].push_back("KHR_gaussian_splatting");
    a.json["extensionsRequired"].push_back("KHR_gaussian_splatting");
    a.Primitive()["extensions"]["KHR_gaussian_splatting"] = Json::object();
    PointCloud from_spz, from_glb;
    ReadPointCloud(dir + "/beside.spz", from_spz);
    ReadPointCloud(a.WriteGlb(dir + "/beside.glb"), from_glb);
    ExpectSameCloud(from_glb, from_spz);

    Json renamed;
    for (const auto& [name, index] : a.Attributes().items()) {
        renamed[name[0] == '_' ? kP + name.substr(1) : name] = index;
    }
    a.Attributes() = renamed;
    PointCloud from_prefixed;
    ReadPointCloud(a.WriteGlb(dir + "/beside_prefixed.glb"), from_prefixed);
    ExpectSameCloud(from_prefixed, from_spz);
}

// A node's TRS applies as for KHR_gaussian_splatting: with M = 2 R and translation t in glTF,
// and C = diag(1, -1, -1) both SPZ -> RDF and glTF -> RDF, a splat read from the .spz at p
// must come out at C (M C p + t), its rotation turned by C R C, its scale doubled, its SH
// turned so that the colour towards C R C d is the .spz colour towards d.
TEST(GltfSpz, NodeTransformAppliesAsForUncompressedSplats) {
    const std::string dir = tests::TempDir();
    const int n = 100;
    const PointCloud cloud = RandomCloud(n, 3, 21);
    Asset a = SpzAsset(SpzBytes(cloud, dir + "/moved.spz"), n, 3);
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 3).normalized()));
    const Eigen::Vector3d t(1.5, -2.0, 0.25);
    a.json["nodes"][0]["rotation"] = {turn.x(), turn.y(), turn.z(), turn.w()};
    a.json["nodes"][0]["scale"] = {2, 2, 2};
    a.json["nodes"][0]["translation"] = {t.x(), t.y(), t.z()};
    PointCloud from_spz, moved;
    ReadPointCloud(dir + "/moved.spz", from_spz);
    ReadPointCloud(a.WriteGlb(dir + "/moved.glb"), moved);
    ASSERT_EQ(moved.NumPoints(), n);
    ASSERT_EQ(moved.GaussianSplatGetSHOrder(), 3);

    const Eigen::Matrix3d C = Eigen::Vector3d(1, -1, -1).asDiagonal();
    const Eigen::Matrix3d R = C * turn.toRotationMatrix() * C;  // the turn in RDF
    const auto col = [](const PointCloud& c, const char* name, int64_t i, int width) {
        return c.GetPointAttr(name).Data<float>() + i * width;
    };
    const int nc = geometry::NumSHRestCoeffs(3);
    std::mt19937 rng(2);
    std::normal_distribution<double> normal;
    for (int64_t i = 0; i < n; ++i) {
        // Positions and scales are computed in double and rounded to float once: within a few
        // float ulps (2^-23 relative) of the exact value.
        const float* p0 = col(from_spz, "positions", i, 3);
        const Eigen::Vector3d expected = 2.0 * R * Eigen::Vector3d(p0[0], p0[1], p0[2]) + C * t;
        const float* p = col(moved, "positions", i, 3);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(p[c], expected[c], 1e-6 * (std::abs(expected[c]) + 1)) << i;
            EXPECT_NEAR(col(moved, "scale", i, 3)[c], 2.0 * col(from_spz, "scale", i, 3)[c],
                        1e-6 * col(from_spz, "scale", i, 3)[c]);
            EXPECT_EQ(col(moved, "f_dc", i, 3)[c], col(from_spz, "f_dc", i, 3)[c]);
        }
        EXPECT_EQ(col(moved, "opacity", i, 1)[0], col(from_spz, "opacity", i, 1)[0]);
        // Rotations: the same three axes turned by R, each possibly reversed (a Gaussian's
        // axes have no direction, so R r0 and r may differ by a diagonal of signs). Float
        // quaternions: 1e-6.
        const float* q0 = col(from_spz, "rot", i, 4);
        const float* q = col(moved, "rot", i, 4);
        const Eigen::Matrix3d r0 =
            Eigen::Quaterniond(q0[0], q0[1], q0[2], q0[3]).toRotationMatrix();
        const Eigen::Matrix3d r = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
        const Eigen::Matrix3d signs = (R * r0).transpose() * r;
        EXPECT_LT((signs.cwiseAbs() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-6)
            << i;
        // SH: coefficients rotated in double and stored as float; the colour sums 16 of them
        // (|c| < 1 here), so 1e-5 leaves room for their rounding.
        for (int trial = 0; trial < 8; ++trial) {
            const Eigen::Vector3d d =
                Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
            const Eigen::Vector3d turned = R * d;
            const auto colour = geometry::EvaluateSH<double>(3, col(from_spz, "f_dc", i, 3),
                                                             col(from_spz, "f_rest", i, nc * 3),
                                                             d.x(), d.y(), d.z());
            const auto moved_colour = geometry::EvaluateSH<double>(
                3, col(moved, "f_dc", i, 3), col(moved, "f_rest", i, nc * 3), turned.x(),
                turned.y(), turned.z());
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(moved_colour[c], colour[c], 1e-5) << i;
        }
    }
}

// Attributes naming fewer SH degrees than the SPZ holds: the named ones are read (CesiumJS
// loads the named attributes only), with a warning.
TEST(GltfSpz, FewerShDegreesNamedThanStored) {
    const std::string dir = tests::TempDir();
    const PointCloud cloud = RandomCloud(30, 3, 8);
    Asset a = SpzAsset(SpzBytes(cloud, dir + "/fewer.spz"), 30, 1);
    PointCloud from_spz, from_glb;
    ReadPointCloud(dir + "/fewer.spz", from_spz);
    const auto warnings =
        tests::CaptureWarnings([&] { ReadPointCloud(a.WriteGlb(dir + "/fewer.glb"), from_glb); });
    ASSERT_EQ(from_glb.GaussianSplatGetSHOrder(), 1);
    bool warned = false;
    for (const auto& w : warnings) warned = warned || w.find("SH degree 3") != std::string::npos;
    EXPECT_TRUE(warned);
    // The .spz cloud with its degree-1 coefficients only (the first 3 of 15).
    PointCloud expected = from_spz;
    Tensor first({30, 3, 3}, core::Dtype::Float32);
    const float* full = from_spz.GetPointAttr("f_rest").Data<float>();
    for (int64_t i = 0; i < 30; ++i) std::copy_n(full + i * 45, 9, first.Data<float>() + i * 9);
    expected.SetPointAttr("f_rest", first);
    ExpectSameCloud(from_glb, expected);
}

// Malformed input: each error names the file and the glTF object at fault, and the cloud is
// left as it was.
TEST(GltfSpz, MalformedFilesNameTheFileAndTheObject) {
    const std::string dir = tests::TempDir();
    const PointCloud cloud = RandomCloud(20, 1, 3);
    const std::vector<uint8_t> spz = SpzBytes(cloud, dir + "/bad.spz");
    const auto variant = [&](const std::string& name, auto edit) {
        Asset a = SpzAsset(spz, 20, 1);
        edit(a);
        return a.WriteGlb(dir + "/bad_" + name + ".glb");
    };
    const std::string at = "mesh 0 primitive 0 " + kSpz;
    ExpectReadError(
        variant("no_view", [&](Asset& a) { a.Primitive()["extensions"][kSpz] = Json::object(); }),
        {at + " has no 'bufferView'"});
    ExpectReadError(variant("view_index",
                            [&](Asset& a) { a.Primitive()["extensions"][kSpz]["bufferView"] = 7; }),
                    {at, "bufferViews[7]"});
    ExpectReadError(variant("not_object", [&](Asset& a) { a.Primitive()["extensions"][kSpz] = 0; }),
                    {at + " is not an object"});
    ExpectReadError(
        variant("view_past_buffer",
                [&](Asset& a) { a.json["bufferViews"][0]["byteLength"] = spz.size() + 64; }),
        {"bufferView 0", "past the end of the buffer", at});
    // Truncated SPZ: inside the TOC, and inside the last stream.
    const std::string in_view = at + " (the SPZ in bufferView 0): ";
    ExpectReadError(
        variant("cut_toc", [&](Asset& a) { a.json["bufferViews"][0]["byteLength"] = 100; }),
        {in_view, "'tocByteOffset'"});
    ExpectReadError(
        variant("cut_stream",
                [&](Asset& a) { a.json["bufferViews"][0]["byteLength"] = spz.size() - 9; }),
        {in_view, "passes the end of the SPZ data"});
    ExpectReadError(variant("not_spz",
                            [&](Asset& a) {
                                for (size_t k = 0; k < 8; ++k) a.bin[k] = uint8_t('x');
                            }),
                    {in_view, "'magic'"});
    ExpectReadError(variant("count", [&](Asset& a) { a.AccessorOf("_SCALE")["count"] = 19; }),
                    {"(_SCALE) has count 19", "holds 20 splats"});
    ExpectReadError(variant("no_rotation", [&](Asset& a) { a.Attributes().erase("_ROTATION"); }),
                    {"mesh 0 primitive 0 has no _ROTATION attribute"});
    ExpectReadError(variant("accessor_index", [&](Asset& a) { a.Attributes()["_SCALE"] = 99; }),
                    {"_SCALE", "accessors[99]"});
    ExpectReadError(
        variant("partial_sh", [&](Asset& a) { a.Attributes().erase("_SH_DEGREE_1_COEF_2"); }),
        {"SH degree 1 is partly defined", "_SH_DEGREE_1_COEF_2"});
    ExpectReadError(variant("sh_beyond",
                            [&](Asset& a) {
                                for (int m = 0; m < 5; ++m) {
                                    a.Attributes()["_SH_DEGREE_2_COEF_" + std::to_string(m)] =
                                        a.AddAccessor(-1, 0, kFloat, "VEC3", 20);
                                }
                            }),
                    {"names SH degree 2", "holds degree 1"});
    ExpectReadError(variant("mode", [&](Asset& a) { a.Primitive()["mode"] = 4; }),
                    {"mode 4", "POINTS"});
    ExpectReadError(
        variant("base_not_object",
                [&](Asset& a) { a.Primitive()["extensions"]["KHR_gaussian_splatting"] = 1; }),
        {"KHR_gaussian_splatting is not an object"});
}

// An accessor with a bufferView is ignored with a warning (the first draft: loaders ignore it);
// the values still come from the SPZ.
TEST(GltfSpz, AccessorStorageIsIgnored) {
    const std::string dir = tests::TempDir();
    const PointCloud cloud = RandomCloud(10, 0, 4);
    Asset a = SpzAsset(SpzBytes(cloud, dir + "/stored.spz"), 10, 0);
    a.AccessorOf("POSITION")["bufferView"] = a.AddView(Raw(std::vector<float>(30, 7.0f)));
    PointCloud from_spz, from_glb;
    ReadPointCloud(dir + "/stored.spz", from_spz);
    const auto warnings =
        tests::CaptureWarnings([&] { ReadPointCloud(a.WriteGlb(dir + "/stored.glb"), from_glb); });
    ExpectSameCloud(from_glb, from_spz);
    bool warned = false;
    for (const auto& w : warnings) {
        warned = warned || w.find("ignored, the values come from the SPZ") != std::string::npos;
    }
    EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
