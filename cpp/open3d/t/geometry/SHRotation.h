// Exact rotation of spherical-harmonics coefficients (degrees 1..3) for the basis of
// SphericalHarmonics.h, and the parity flip that a point inversion (negative scale) needs.
// Band matrices come from the Ivanic-Ruedenberg recursion (J. Phys. Chem. 1996, with the
// 1998 erratum) and are conjugated by the Condon-Shortley signs of our basis.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>

namespace open3d {
namespace t {
namespace geometry {

/// Largest SH degree the rotation supports (the 3DGS maximum).
inline constexpr int kMaxSHRotationDegree = 3;

/// The band matrices of one 3D rotation R, for SH degrees 1..degree.
///
/// For the coefficients c_l of band l (basis order m = -l..l as in SphericalHarmonics.h),
/// c_l' = GetBand(l) * c_l satisfies EvaluateSH(c', R d) == EvaluateSH(c, d) for every
/// direction d: the colour pattern turns with the splat. Degree 0 (f_dc) is invariant.
class SHRotation {
public:
    /// R must be a proper rotation (det +1, orthonormal); this is not checked here
    /// (PointCloud::Rotate validates). degree in [0, 3]; degree 0 builds no bands.
    SHRotation(const Eigen::Matrix3d& R, int degree);

    int GetDegree() const { return degree_; }
    /// True when R was exactly the identity: Apply then leaves data bit-exact.
    bool IsIdentity() const { return is_identity_; }

    /// The (2l+1) x (2l+1) orthogonal matrix of band l, 1 <= l <= GetDegree().
    Eigen::MatrixXd GetBand(int l) const;

    /// Rotates one splat's f_rest block in place: [Nc, 3] with Nc = (degree+1)^2 - 1,
    /// coefficient k = l^2 + l + m - 1, last axis RGB. The same band matrix acts on R, G
    /// and B. Arithmetic is in double; results are rounded once to float.
    void Apply(float* f_rest) const;

private:
    int degree_ = 0;
    bool is_identity_ = false;
    // Band l stored row-major at offset kBandOffset[l]; 9 + 25 + 49 doubles.
    static constexpr std::array<int, 4> kBandOffset = {0, 0, 9, 34};
    std::array<double, 83> bands_{};
};

/// Rotates f_rest [num_splats, Nc, 3] in place, in parallel over splats.
/// Nc = (degree+1)^2 - 1; nothing happens for degree 0.
void RotateSHRest(const SHRotation& rotation, int64_t num_splats, float* f_rest);

/// Applies the parity of a point inversion d -> -d, Y_lm(-d) = (-1)^l Y_lm(d), to
/// f_rest [num_splats, Nc, 3] in place: odd bands (l = 1, 3) are negated, even bands kept.
/// Afterwards EvaluateSH(result, -d) == EvaluateSH(original, d) exactly.
void ApplySHParity(int degree, int64_t num_splats, float* f_rest);

}  // namespace geometry
}  // namespace t
}  // namespace open3d
