// Transforms of point clouds and Gaussian splat clouds: every attribute must follow the
// geometry (covariance, view-dependent colour), and a refused transform changes nothing.
#include <gtest/gtest.h>

#include "RandomGeometry.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace geometry {
namespace {

using core::Dtype;
using core::Tensor;

PointCloud MakePlainCloud(int64_t n, uint32_t seed) {
    std::mt19937 rng(seed);
    return PointCloud(RandomTensor(rng, {n, 3}, -5.f, 5.f));
}

// Sigma = R_q S^2 R_q^T, as the renderer builds it from the stored attributes.
Eigen::Matrix3d Covariance(const PointCloud& cloud, int64_t i) {
    const float* q = cloud.GetPointAttr(gs_attr::kRot).Data<float>() + 4 * i;
    const float* s = cloud.GetPointAttr(gs_attr::kScale).Data<float>() + 3 * i;
    const Eigen::Matrix3d r =
        Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
    const Eigen::Vector3d s2(double(s[0]) * s[0], double(s[1]) * s[1], double(s[2]) * s[2]);
    return r * s2.asDiagonal() * r.transpose();
}

std::array<double, 3> Colour(const PointCloud& cloud, int degree, int64_t i,
                             const Eigen::Vector3d& d) {
    const float* f_dc = cloud.GetPointAttr(gs_attr::kFDc).Data<float>() + 3 * i;
    const float* f_rest = degree > 0 ? cloud.GetPointAttr(gs_attr::kFRest).Data<float>() +
                                           i * NumSHRestCoeffs(degree) * 3
                                     : nullptr;
    return EvaluateSH<double>(degree, f_dc, f_rest, d.x(), d.y(), d.z());
}

// Largest relative change of a covariance: |A - B|_max / |B|_max.
double CovarianceError(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
    return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

TEST(PointCloudTransform, GetCenter) {
    EXPECT_EQ(PointCloud().GetCenter(), Eigen::Vector3d::Zero());
    PointCloud cloud(Tensor::FromVector<float>({0, 0, 0, 2, 4, 6}, {2, 3}));
    EXPECT_EQ(cloud.GetCenter(), Eigen::Vector3d(1, 2, 3));
}

TEST(PointCloudTransform, TranslateMovesPositionsOnly) {
    const PointCloud original = MakeSplatCloud(1000, 3, 1);
    PointCloud cloud = original;
    const Eigen::Vector3d t(1.5, -2.0, 0.25);
    cloud.Translate(t);
    for (int64_t i = 0; i < cloud.NumPoints(); ++i) {
        const Eigen::Vector3d expected = Position(original, i) + t;
        ASSERT_EQ(Position(cloud, i), expected.cast<float>().cast<double>()) << i;
    }
    for (const char* name :
         {gs_attr::kScale, gs_attr::kRot, gs_attr::kOpacity, gs_attr::kFDc, gs_attr::kFRest}) {
        EXPECT_EQ(cloud.GetPointAttr(name), original.GetPointAttr(name)) << name;
    }
    cloud.Translate(Eigen::Vector3d(10, 20, 30), /*relative=*/false);
    const double center_error = (cloud.GetCenter() - Eigen::Vector3d(10, 20, 30)).norm();
    RecordProperty("center_error", Sci(center_error));
    // Float rounding of 1000 positions up to ~35 (half an ulp: 1.9e-6), averaged;
    // measured 1.8e-7, tolerance 1e-5.
    EXPECT_LT(center_error, 1e-5);
    EXPECT_THROW(cloud.Translate(Eigen::Vector3d(std::nan(""), 0, 0)), core::Open3DError);
}

TEST(PointCloudTransform, RotatePlainCloud) {
    const PointCloud original = MakePlainCloud(5000, 2);
    PointCloud cloud = original;
    std::mt19937 rng(3);
    const Eigen::Matrix3d R = RandomRotation(rng);
    const Eigen::Vector3d center(1, -2, 3);
    cloud.Rotate(R, center);
    EXPECT_EQ(cloud.GetPointAttrNames(), original.GetPointAttrNames());
    double max_error = 0.0;
    for (int64_t i = 0; i < cloud.NumPoints(); ++i) {
        const Eigen::Vector3d expected = R * (Position(original, i) - center) + center;
        max_error = std::max(max_error, (Position(cloud, i) - expected).cwiseAbs().maxCoeff());
    }
    // One float rounding of coordinates up to ~14 (half an ulp: 4.8e-7); measured 4.8e-7
    // over 5000 points, tolerance 1e-6.
    RecordProperty("max_error", Sci(max_error));
    EXPECT_LE(max_error, 1e-6);
}

TEST(PointCloudTransform, RotateSplatCloudFollowsCovarianceAndColour) {
    for (int degree = 0; degree <= 3; ++degree) {
        const PointCloud original = MakeSplatCloud(2000, degree, 10 + degree);
        PointCloud cloud = original;
        std::mt19937 rng(20 + degree);
        const Eigen::Matrix3d R = RandomRotation(rng);
        const Eigen::Vector3d center = original.GetCenter();
        cloud.Rotate(R, center);
        for (const char* name : {gs_attr::kScale, gs_attr::kOpacity, gs_attr::kFDc}) {
            EXPECT_EQ(cloud.GetPointAttr(name), original.GetPointAttr(name)) << name;
        }
        double max_position_error = 0.0, max_covariance_error = 0.0, max_colour_error = 0.0;
        for (int64_t i = 0; i < cloud.NumPoints(); ++i) {
            const Eigen::Vector3d expected = R * (Position(original, i) - center) + center;
            max_position_error =
                std::max(max_position_error, (Position(cloud, i) - expected).cwiseAbs().maxCoeff());
            // q' = q_R * q must give R_q' S^2 R_q'^T = R Sigma R^T.
            const Eigen::Matrix3d sigma = R * Covariance(original, i) * R.transpose();
            max_covariance_error =
                std::max(max_covariance_error, CovarianceError(Covariance(cloud, i), sigma));
            for (int k = 0; k < 4; ++k) {
                const Eigen::Vector3d d = RandomDirection(rng);
                const auto before = Colour(original, degree, i, d);
                const auto after = Colour(cloud, degree, i, R * d);
                for (int c = 0; c < 3; ++c) {
                    max_colour_error = std::max(max_colour_error, std::abs(after[c] - before[c]));
                }
            }
        }
        RecordProperty("max_position_error_" + std::to_string(degree), Sci(max_position_error));
        RecordProperty("max_covariance_error_" + std::to_string(degree), Sci(max_covariance_error));
        RecordProperty("max_colour_error_" + std::to_string(degree), Sci(max_colour_error));
        // Positions: one float rounding (|p - center| <= ~9): measured 2.4e-7, tolerance 1e-6.
        EXPECT_LE(max_position_error, 1e-6) << degree;
        // Covariance: the new quaternion is rounded to float (6e-8 per component) and the
        // error doubles through R_q S^2 R_q^T: measured 1.0e-7 relative over 8000 splats,
        // tolerance 1e-6.
        EXPECT_LE(max_covariance_error, 1e-6) << degree;
        // Colour: float rounding of rotated coefficients; measured 6.9e-8 (0 for degree 0),
        // tolerance 1e-6 (as SHRotation.EvaluationInvariantFloat).
        EXPECT_LE(max_colour_error, 1e-6) << degree;
    }
}

TEST(PointCloudTransform, RotateCompositionOnCloud) {
    const PointCloud original = MakeSplatCloud(2000, 3, 30);
    std::mt19937 rng(31);
    const Eigen::Matrix3d a = RandomRotation(rng), b = RandomRotation(rng);
    const Eigen::Vector3d center(0.5, 0.25, -1);
    PointCloud twice = original, once = original;
    twice.Rotate(a, center).Rotate(b, center);
    once.Rotate(b * a, center);
    double max_position_error = 0.0, max_covariance_error = 0.0;
    for (int64_t i = 0; i < original.NumPoints(); ++i) {
        max_position_error = std::max(
            max_position_error, (Position(twice, i) - Position(once, i)).cwiseAbs().maxCoeff());
        max_covariance_error = std::max(max_covariance_error,
                                        CovarianceError(Covariance(twice, i), Covariance(once, i)));
    }
    const float* f_twice = twice.GetPointAttr(gs_attr::kFRest).Data<float>();
    const float* f_once = once.GetPointAttr(gs_attr::kFRest).Data<float>();
    float max_sh_error = 0.f;
    for (int64_t i = 0; i < original.NumPoints() * 15 * 3; ++i) {
        max_sh_error = std::max(max_sh_error, std::abs(f_twice[i] - f_once[i]));
    }
    RecordProperty("max_position_error", Sci(max_position_error));
    RecordProperty("max_covariance_error", Sci(max_covariance_error));
    RecordProperty("max_sh_error", Sci(max_sh_error));
    // Two float roundings against one in each attribute: positions measured 4.8e-7
    // (|p| <= ~10), tolerance 4e-6; covariance measured 1.8e-7 relative, tolerance 2e-6;
    // SH measured 1.2e-7 (|c| <= ~1.7), tolerance 1e-6.
    EXPECT_LE(max_position_error, 4e-6);
    EXPECT_LE(max_covariance_error, 2e-6);
    EXPECT_LE(max_sh_error, 1e-6f);
}

TEST(PointCloudTransform, RotateByIdentityIsBitExact) {
    const PointCloud original = MakeSplatCloud(1000, 3, 40);
    PointCloud cloud = original;
    cloud.Rotate(Eigen::Matrix3d::Identity(), Eigen::Vector3d(3, -1, 2));
    EXPECT_TRUE(cloud == original);
}

TEST(PointCloudTransform, RotateRefusesImproperMatrices) {
    std::mt19937 rng(50);
    const Eigen::Matrix3d R = RandomRotation(rng);
    Eigen::Matrix3d shear = Eigen::Matrix3d::Identity();
    shear(0, 1) = 0.1;
    Eigen::Matrix3d nearly = R;
    nearly(1, 2) += 1e-5;  // 10x the tolerance
    Eigen::Matrix3d nan = R;
    nan(0, 0) = std::numeric_limits<double>::quiet_NaN();
    const Eigen::Matrix3d refused[] = {
        R * Eigen::Vector3d(1, 1, -1).asDiagonal(),  // reflection, det -1
        -R,                                          // point inversion, det -1
        1.01 * R,                                    // rotation with scaling
        shear * R,
        nearly,
        nan,
        Eigen::Matrix3d::Zero()};
    for (const PointCloud& original : {MakeSplatCloud(100, 3, 51), MakePlainCloud(100, 52)}) {
        for (const Eigen::Matrix3d& m : refused) {
            PointCloud cloud = original;
            EXPECT_THROW(cloud.Rotate(m, Eigen::Vector3d::Zero()), core::Open3DError) << m;
            EXPECT_TRUE(cloud == original);
        }
        // A rotation that went through float (camera poses) is orthonormal to ~1e-7: accepted.
        PointCloud cloud = original;
        EXPECT_NO_THROW(cloud.Rotate(R.cast<float>().cast<double>(), Eigen::Vector3d::Zero()));
    }
}

TEST(PointCloudTransform, RotateRefusesMalformedSplatCloud) {
    const int64_t n = 10;
    PointCloud original = MakeSplatCloud(n, 1, 60);
    original.SetPointAttr(gs_attr::kRot, Tensor({n, 3}, Dtype::Float32));  // not a quaternion
    PointCloud cloud = original;
    EXPECT_THROW(cloud.Rotate(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()),
                 core::Open3DError);
    EXPECT_THROW(cloud.Scale(2.0, Eigen::Vector3d::Zero()), core::Open3DError);
    EXPECT_TRUE(cloud == original);
}

TEST(PointCloudTransform, ScalePositive) {
    const PointCloud original = MakeSplatCloud(1000, 3, 70);
    PointCloud cloud = original;
    const Eigen::Vector3d center(1, 2, 3);
    cloud.Scale(2.5, center);
    const float* s0 = original.GetPointAttr(gs_attr::kScale).Data<float>();
    const float* s1 = cloud.GetPointAttr(gs_attr::kScale).Data<float>();
    for (int64_t i = 0; i < original.NumPoints(); ++i) {
        const Eigen::Vector3d expected = 2.5 * (Position(original, i) - center) + center;
        // One float rounding of values up to ~20: half an ulp is 9.5e-7; tolerance 2e-6.
        ASSERT_LE((Position(cloud, i) - expected).cwiseAbs().maxCoeff(), 2e-6) << i;
        for (int k = 0; k < 3; ++k) ASSERT_EQ(s1[3 * i + k], float(2.5 * s0[3 * i + k]));
    }
    for (const char* name : {gs_attr::kRot, gs_attr::kOpacity, gs_attr::kFDc, gs_attr::kFRest}) {
        EXPECT_EQ(cloud.GetPointAttr(name), original.GetPointAttr(name)) << name;
    }
}

TEST(PointCloudTransform, ScaleNegativeIsPointInversion) {
    for (int degree = 0; degree <= 3; ++degree) {
        const PointCloud original = MakeSplatCloud(500, degree, 80 + degree);
        PointCloud cloud = original;
        const Eigen::Vector3d center(0.5, -0.5, 2);
        cloud.Scale(-2.0, center);
        EXPECT_EQ(cloud.GetPointAttr(gs_attr::kRot), original.GetPointAttr(gs_attr::kRot));
        EXPECT_EQ(cloud.GetPointAttr(gs_attr::kFDc), original.GetPointAttr(gs_attr::kFDc));
        std::mt19937 rng(90);
        for (int64_t i = 0; i < original.NumPoints(); ++i) {
            const Eigen::Vector3d expected = -2.0 * (Position(original, i) - center) + center;
            ASSERT_LE((Position(cloud, i) - expected).cwiseAbs().maxCoeff(), 2e-6) << i;
            // Covariance scales by s^2 = 4 (|s| on the linear scales, exact in float).
            ASSERT_LE(CovarianceError(Covariance(cloud, i), 4.0 * Covariance(original, i)), 1e-12);
            for (int k = 0; k < 5; ++k) {
                // The point inversion maps a view direction d to -d; negation is exact, so
                // the colours agree bit for bit.
                const Eigen::Vector3d d = RandomDirection(rng);
                ASSERT_EQ(Colour(cloud, degree, i, -d), Colour(original, degree, i, d)) << i;
            }
        }
    }
}

TEST(PointCloudTransform, ScaleZero) {
    PointCloud splats = MakeSplatCloud(10, 1, 100);
    const PointCloud original = splats;
    EXPECT_THROW(splats.Scale(0.0, Eigen::Vector3d::Zero()), core::Open3DError);
    EXPECT_THROW(splats.Scale(std::nan(""), Eigen::Vector3d::Zero()), core::Open3DError);
    EXPECT_TRUE(splats == original);
    // A plain cloud may collapse onto the center.
    PointCloud plain = MakePlainCloud(10, 101);
    plain.Scale(0.0, Eigen::Vector3d(1, 2, 3));
    for (int64_t i = 0; i < plain.NumPoints(); ++i) {
        EXPECT_EQ(Position(plain, i), Eigen::Vector3d(1, 2, 3));
    }
}

TEST(PointCloudTransform, TransformMovesPositionsAndWarnsForSplats) {
    std::mt19937 rng(110);
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = RandomRotation(rng) * Eigen::Vector3d(1, 2, 3).asDiagonal();
    m.topRightCorner<3, 1>() = Eigen::Vector3d(4, 5, 6);

    std::vector<std::string> warnings;
    const core::LogSink previous = core::SetLogSink([&](core::LogLevel level, std::string_view s) {
        if (level == core::LogLevel::Warning) warnings.emplace_back(s);
    });
    const PointCloud splat_original = MakeSplatCloud(100, 2, 111);
    PointCloud splats = splat_original;
    splats.Transform(m);
    PointCloud plain = MakePlainCloud(100, 112);
    const PointCloud plain_original = plain;
    plain.Transform(m);
    core::SetLogSink(previous);

    ASSERT_EQ(warnings.size(), 1u);  // the splat cloud only
    EXPECT_NE(warnings[0].find("unchanged"), std::string::npos) << warnings[0];
    for (const char* name :
         {gs_attr::kScale, gs_attr::kRot, gs_attr::kOpacity, gs_attr::kFDc, gs_attr::kFRest}) {
        EXPECT_EQ(splats.GetPointAttr(name), splat_original.GetPointAttr(name)) << name;
    }
    for (int64_t i = 0; i < plain.NumPoints(); ++i) {
        const Eigen::Vector3d expected =
            m.topLeftCorner<3, 3>() * Position(plain_original, i) + m.topRightCorner<3, 1>();
        // One float rounding of values up to ~40: half an ulp is 1.9e-6.
        ASSERT_LE((Position(plain, i) - expected).cwiseAbs().maxCoeff(), 4e-6) << i;
    }

    Eigen::Matrix4d projective = Eigen::Matrix4d::Identity();
    projective(3, 2) = 1.0;
    EXPECT_THROW(plain.Transform(projective), core::Open3DError);
}

// The shared playbot scene, rotated and rotated back: every attribute returns to the
// file's values within float rounding, and the colour follows the rotation.
TEST(PointCloudTransform, PlaybotRotateAndBack) {
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    PointCloud original;
    io::ReadPointCloud(tests::DataPath("playbot/playbot_31k.ply"), original);
    ASSERT_TRUE(original.IsGaussianSplat());
    const int degree = original.GaussianSplatGetSHOrder();
    const int64_t n = original.NumPoints();

    std::mt19937 rng(120);
    const Eigen::Matrix3d R = RandomRotation(rng);
    const Eigen::Vector3d center = original.GetCenter();
    PointCloud rotated = original;
    rotated.Rotate(R, center);

    double max_colour_error = 0.0, max_colour = 0.0;
    for (int64_t i = 0; i < n; ++i) {
        const Eigen::Vector3d d = RandomDirection(rng);
        const auto before = Colour(original, degree, i, d);
        const auto after = Colour(rotated, degree, i, R * d);
        for (int c = 0; c < 3; ++c) {
            max_colour_error = std::max(max_colour_error, std::abs(after[c] - before[c]));
            max_colour = std::max(max_colour, std::abs(before[c]));
        }
    }

    PointCloud back = rotated;
    back.Rotate(R.transpose(), center);
    for (const char* name : {gs_attr::kScale, gs_attr::kOpacity, gs_attr::kFDc}) {
        EXPECT_EQ(back.GetPointAttr(name), original.GetPointAttr(name)) << name;
    }
    double max_position_error = 0.0, max_quaternion_error = 0.0, max_extent = 0.0;
    for (int64_t i = 0; i < n; ++i) {
        max_position_error = std::max(
            max_position_error, (Position(back, i) - Position(original, i)).cwiseAbs().maxCoeff());
        max_extent = std::max(max_extent, (Position(original, i) - center).cwiseAbs().maxCoeff());
        // q and -q are the same rotation; compare the normalised quaternions up to sign.
        const float* q0 = original.GetPointAttr(gs_attr::kRot).Data<float>() + 4 * i;
        const float* q1 = back.GetPointAttr(gs_attr::kRot).Data<float>() + 4 * i;
        const Eigen::Vector4d a = Eigen::Vector4d(q0[0], q0[1], q0[2], q0[3]).normalized();
        const Eigen::Vector4d b = Eigen::Vector4d(q1[0], q1[1], q1[2], q1[3]).normalized();
        max_quaternion_error =
            std::max(max_quaternion_error, std::min((a - b).norm(), (a + b).norm()));
    }
    double max_sh_error = 0.0, max_sh = 0.0;
    if (degree > 0) {
        const float* f0 = original.GetPointAttr(gs_attr::kFRest).Data<float>();
        const float* f1 = back.GetPointAttr(gs_attr::kFRest).Data<float>();
        for (int64_t i = 0; i < n * NumSHRestCoeffs(degree) * 3; ++i) {
            max_sh_error = std::max(max_sh_error, double(std::abs(f1[i] - f0[i])));
            max_sh = std::max(max_sh, double(std::abs(f0[i])));
        }
    }
    RecordProperty("sh_degree", degree);
    RecordProperty("max_colour_error", Sci(max_colour_error));
    RecordProperty("max_colour", Sci(max_colour));
    RecordProperty("max_position_error", Sci(max_position_error));
    RecordProperty("max_extent", Sci(max_extent));
    RecordProperty("max_quaternion_error", Sci(max_quaternion_error));
    RecordProperty("max_sh_error", Sci(max_sh_error));
    RecordProperty("max_sh", Sci(max_sh));
    // Measured on playbot_31k (SH degree 2, |p - center| <= 1.04, |f_rest| <= 2.9,
    // |colour| <= 3.4): colour 3.8e-8 (tolerance 1e-6), positions after the round trip
    // 6.0e-8 (tolerance 1e-6, ~8 ulps at this extent), quaternion 6.4e-8 (tolerance
    // 1e-6), f_rest 1.2e-7 (tolerance 1e-6, ~4 ulps at |c| ~ 2.9).
    EXPECT_LE(max_colour_error, 1e-6);
    EXPECT_LE(max_position_error, 1e-6);
    EXPECT_LE(max_quaternion_error, 1e-6);
    EXPECT_LE(max_sh_error, 1e-6);
}

}  // namespace
}  // namespace geometry
}  // namespace t
}  // namespace open3d
