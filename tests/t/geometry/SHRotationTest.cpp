// SH rotation is judged by what it is for: the rotated coefficients, evaluated with the
// basis of SphericalHarmonics.h at R d, must give the colour the original gave at d.
#include "open3d/t/geometry/SHRotation.h"

#include <gtest/gtest.h>

#include "RandomGeometry.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "open3d/t/geometry/SphericalHarmonics.h"

namespace open3d {
namespace t {
namespace geometry {
namespace {

// Basis values of band l (2l+1 of them) at a unit direction.
Eigen::VectorXd BandBasis(int l, const Eigen::Vector3d& d) {
    double basis[16];
    EvaluateSHBasis<double>(3, d.x(), d.y(), d.z(), basis);
    return Eigen::Map<Eigen::VectorXd>(basis + l * l, 2 * l + 1);
}

std::vector<float> RandomCoeffs(std::mt19937& rng, int64_t count) {
    // 3DGS f_rest values are O(0.1-1); uniform [-1, 1] covers that range.
    std::uniform_real_distribution<float> uniform(-1.f, 1.f);
    std::vector<float> values(count);
    for (auto& v : values) v = uniform(rng);
    return values;
}

TEST(SHRotation, BandMatricesAreOrthogonal) {
    std::mt19937 rng(1);
    double max_error = 0.0;
    for (int trial = 0; trial < 1000; ++trial) {
        const SHRotation rotation(RandomRotation(rng), 3);
        for (int l = 1; l <= 3; ++l) {
            const Eigen::MatrixXd b = rotation.GetBand(l);
            const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(2 * l + 1, 2 * l + 1);
            max_error = std::max(max_error, (b * b.transpose() - identity).cwiseAbs().maxCoeff());
        }
    }
    // Max error measured 4.4e-15 over 1000 rotations x 3 bands (a few ulps of the
    // recursion's sums); tolerance 1e-13 leaves room for other compilers and FMA.
    RecordProperty("max_error", Sci(max_error));
    EXPECT_LT(max_error, 1e-13);
}

TEST(SHRotation, IdentityIsExact) {
    const SHRotation rotation(Eigen::Matrix3d::Identity(), 3);
    EXPECT_TRUE(rotation.IsIdentity());
    // The recursion itself yields the exact identity, not only the Apply shortcut.
    for (int l = 1; l <= 3; ++l) {
        EXPECT_EQ(rotation.GetBand(l), Eigen::MatrixXd::Identity(2 * l + 1, 2 * l + 1)) << l;
    }
    std::mt19937 rng(2);
    std::vector<float> coeffs = RandomCoeffs(rng, 100 * 15 * 3);
    coeffs[0] = -0.0f;  // signed zero and NaN must survive untouched
    coeffs[1] = std::numeric_limits<float>::quiet_NaN();
    const std::vector<float> original = coeffs;
    RotateSHRest(rotation, 100, coeffs.data());
    EXPECT_EQ(std::memcmp(coeffs.data(), original.data(), coeffs.size() * sizeof(float)), 0);
}

TEST(SHRotation, DegreeOneIsThePermutedMatrixWithSigns) {
    // Band 1 acts on (-y, z, -x) coefficients: R permuted to (y, z, x), conjugated by
    // diag(-1, 1, -1). Written out so the convention is visible in one place.
    std::mt19937 rng(3);
    const Eigen::Matrix3d R = RandomRotation(rng);
    const int idx[3] = {1, 2, 0};
    const double sign[3] = {-1, 1, -1};
    const Eigen::MatrixXd b = SHRotation(R, 1).GetBand(1);
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) EXPECT_EQ(b(i, j), sign[i] * sign[j] * R(idx[i], idx[j]));
    }
}

// An oracle independent of Ivanic-Ruedenberg: the band matrix B is the unique solution
// of B^T Y_l(R d) = Y_l(d) for all d, found by least squares over sample directions.
TEST(SHRotation, MatchesLeastSquaresFitOfTheBasis) {
    std::mt19937 rng(4);
    double max_error = 0.0;
    for (int trial = 0; trial < 100; ++trial) {
        const Eigen::Matrix3d R = RandomRotation(rng);
        const SHRotation rotation(R, 3);
        for (int l = 1; l <= 3; ++l) {
            const int n = 2 * l + 1;
            const int samples = 64;
            Eigen::MatrixXd a(samples, n), target(samples, n);
            for (int k = 0; k < samples; ++k) {
                const Eigen::Vector3d d = RandomDirection(rng);
                a.row(k) = BandBasis(l, R * d).transpose();
                target.row(k) = BandBasis(l, d).transpose();
            }
            const Eigen::MatrixXd fit = a.colPivHouseholderQr().solve(target);
            max_error = std::max(max_error, (fit - rotation.GetBand(l)).cwiseAbs().maxCoeff());
        }
    }
    // Max error measured 2.7e-15 over 100 rotations x 3 bands (64 well-spread samples keep
    // the fit well conditioned); tolerance 1e-12. A sign error shows up as O(1).
    RecordProperty("max_error", Sci(max_error));
    EXPECT_LT(max_error, 1e-12);
}

// Double path: band matrices applied in double, basis evaluated in double. This is the
// exactness of the construction itself, free of float storage.
TEST(SHRotation, EvaluationInvariantDouble) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    double max_error = 0.0;
    for (int degree = 1; degree <= 3; ++degree) {
        for (int trial = 0; trial < 200; ++trial) {
            const Eigen::Matrix3d R = RandomRotation(rng);
            const SHRotation rotation(R, degree);
            std::vector<Eigen::VectorXd> coeffs, rotated;
            for (int l = 1; l <= degree; ++l) {
                coeffs.push_back(
                    Eigen::VectorXd::NullaryExpr(2 * l + 1, [&] { return uniform(rng); }));
                rotated.push_back(rotation.GetBand(l) * coeffs.back());
            }
            for (int k = 0; k < 50; ++k) {
                const Eigen::Vector3d d = RandomDirection(rng);
                const Eigen::Vector3d rd = R * d;
                double before = 0.0, after = 0.0;
                for (int l = 1; l <= degree; ++l) {
                    before += BandBasis(l, d).dot(coeffs[l - 1]);
                    after += BandBasis(l, rd).dot(rotated[l - 1]);
                }
                max_error = std::max(max_error, std::abs(after - before));
            }
        }
    }
    // Max error measured 3.6e-15 over 30k (rotation, direction) pairs with |c| <= 1
    // (sums of up to 15 terms of size <= 3); tolerance 1e-12.
    RecordProperty("max_error", Sci(max_error));
    EXPECT_LT(max_error, 1e-12);
}

// Float path, as the cloud stores it: f_rest [N, Nc, 3] float rotated by RotateSHRest,
// then the colour evaluated as the renderer does.
TEST(SHRotation, EvaluationInvariantFloat) {
    std::mt19937 rng(6);
    double max_error_double_eval = 0.0;
    float max_error_float_eval = 0.f;
    for (int degree = 1; degree <= 3; ++degree) {
        const int nc = NumSHBasis(degree) - 1;
        for (int trial = 0; trial < 50; ++trial) {
            const Eigen::Matrix3d R = RandomRotation(rng);
            const int64_t n = 20;
            const std::vector<float> original = RandomCoeffs(rng, n * nc * 3);
            std::vector<float> rotated = original;
            RotateSHRest(SHRotation(R, degree), n, rotated.data());
            const float f_dc[3] = {0.5f, -0.25f, 0.125f};
            for (int64_t i = 0; i < n; ++i) {
                const float* before = original.data() + i * nc * 3;
                const float* after = rotated.data() + i * nc * 3;
                for (int k = 0; k < 20; ++k) {
                    const Eigen::Vector3d d = RandomDirection(rng);
                    const Eigen::Vector3d rd = R * d;
                    const auto c0 = EvaluateSH<double>(degree, f_dc, before, d.x(), d.y(), d.z());
                    const auto c1 = EvaluateSH<double>(degree, f_dc, after, rd.x(), rd.y(), rd.z());
                    const Eigen::Vector3f df = d.cast<float>(), rdf = rd.cast<float>();
                    const auto f0 = EvaluateSH<float>(degree, f_dc, before, df.x(), df.y(), df.z());
                    const auto f1 =
                        EvaluateSH<float>(degree, f_dc, after, rdf.x(), rdf.y(), rdf.z());
                    for (int c = 0; c < 3; ++c) {
                        max_error_double_eval =
                            std::max(max_error_double_eval, std::abs(c1[c] - c0[c]));
                        max_error_float_eval =
                            std::max(max_error_float_eval, std::abs(f1[c] - f0[c]));
                    }
                }
            }
        }
    }
    // Only the float rounding of each rotated coefficient (<= 6e-8 relative) remains:
    // max error measured 7.9e-8 (double evaluation) over 60k colours x 3 channels,
    // tolerance 1e-6; float evaluation adds its own rounding at both ends (float direction,
    // float basis, float sums): measured 7.2e-7, tolerance 5e-6. One colour step of
    // 1/255 = 3.9e-3 is far above either.
    EXPECT_LT(max_error_double_eval, 1e-6);
    EXPECT_LT(max_error_float_eval, 5e-6f);
    RecordProperty("max_error_double_eval", Sci(max_error_double_eval));
    RecordProperty("max_error_float_eval", Sci(max_error_float_eval));
}

TEST(SHRotation, CompositionIsTheMatrixProduct) {
    std::mt19937 rng(7);
    double max_error = 0.0;
    for (int trial = 0; trial < 500; ++trial) {
        const Eigen::Matrix3d a = RandomRotation(rng);
        const Eigen::Matrix3d b = RandomRotation(rng);
        const SHRotation ra(a, 3), rb(b, 3), rba(b * a, 3);
        for (int l = 1; l <= 3; ++l) {
            const Eigen::MatrixXd composed = rb.GetBand(l) * ra.GetBand(l);
            max_error = std::max(max_error, (composed - rba.GetBand(l)).cwiseAbs().maxCoeff());
        }
    }
    // Max error measured 8.5e-16 over 500 pairs x 3 bands; tolerance 1e-13.
    RecordProperty("max_error", Sci(max_error));
    EXPECT_LT(max_error, 1e-13);
}

TEST(SHRotation, CompositionOnStoredCoefficients) {
    // Rotating f_rest by A, then by B, equals rotating by B*A once (up to float rounding).
    std::mt19937 rng(8);
    const Eigen::Matrix3d a = RandomRotation(rng), b = RandomRotation(rng);
    const int64_t n = 1000;
    const std::vector<float> original = RandomCoeffs(rng, n * 15 * 3);
    std::vector<float> twice = original, once = original;
    RotateSHRest(SHRotation(a, 3), n, twice.data());
    RotateSHRest(SHRotation(b, 3), n, twice.data());
    RotateSHRest(SHRotation(b * a, 3), n, once.data());
    float max_error = 0.f;
    for (size_t i = 0; i < once.size(); ++i) {
        max_error = std::max(max_error, std::abs(once[i] - twice[i]));
    }
    // Two float roundings against one: measured 1.2e-7 (2 ulps at |c| ~ 1), tolerance 1e-6.
    RecordProperty("max_error", Sci(max_error));
    EXPECT_LT(max_error, 1e-6f);
}

TEST(SHRotation, ParityNegatesOddBands) {
    std::mt19937 rng(9);
    for (int degree = 1; degree <= 3; ++degree) {
        const int nc = NumSHBasis(degree) - 1;
        const int64_t n = 200;
        const std::vector<float> original = RandomCoeffs(rng, n * nc * 3);
        std::vector<float> flipped = original;
        ApplySHParity(degree, n, flipped.data());
        const float f_dc[3] = {0.5f, -0.25f, 0.125f};
        for (int64_t i = 0; i < n; ++i) {
            for (int k = 0; k < 10; ++k) {
                const Eigen::Vector3f d = RandomDirection(rng).cast<float>();
                const auto before = EvaluateSH<float>(degree, f_dc, original.data() + i * nc * 3,
                                                      d.x(), d.y(), d.z());
                const auto after = EvaluateSH<float>(degree, f_dc, flipped.data() + i * nc * 3,
                                                     -d.x(), -d.y(), -d.z());
                // Negating d flips the sign of every odd basis function exactly in IEEE
                // arithmetic, so the sums match bit for bit.
                for (int c = 0; c < 3; ++c) ASSERT_EQ(after[c], before[c]) << degree;
            }
        }
    }
}

TEST(SHRotation, RejectsUnsupportedDegree) {
    EXPECT_THROW(SHRotation(Eigen::Matrix3d::Identity(), 4), std::exception);
    EXPECT_THROW(SHRotation(Eigen::Matrix3d::Identity(), -1), std::exception);
    float coeffs[3] = {};
    EXPECT_THROW(ApplySHParity(4, 1, coeffs), std::exception);
    // Degree 0 has nothing to rotate: no band, no effect.
    const SHRotation none(Eigen::Matrix3d::Identity(), 0);
    EXPECT_THROW(none.GetBand(1), std::exception);
}

}  // namespace
}  // namespace geometry
}  // namespace t
}  // namespace open3d
