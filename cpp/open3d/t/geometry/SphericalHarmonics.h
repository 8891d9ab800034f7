// Real spherical-harmonics basis exactly as the 3DGS rasterizer evaluates it (degree 0..3).
// Basis index j = l^2 + l + m (j = 0 is the DC term); f_rest coefficient k = j - 1.
// Degree 1 is ordered m = -1, 0, +1, i.e. Cartesian (y, z, x), with the signs of the
// Condon-Shortley phase: -C1*y, +C1*z, -C1*x. Shared by the CPU reference, the SH
// rotation and its tests, so there is one definition of "the SH colour".
#pragma once

#include <array>

namespace open3d {
namespace t {
namespace geometry {

inline constexpr double kSH_C0 = 0.28209479177387814;
inline constexpr double kSH_C1 = 0.4886025119029199;
inline constexpr double kSH_C2[5] = {1.0925484305920792, -1.0925484305920792, 0.31539156525252005,
                                     -1.0925484305920792, 0.5462742152960396};
inline constexpr double kSH_C3[7] = {-0.5900435899266435, 2.890611442640554,   -0.4570457994644658,
                                     0.3731763325901154,  -0.4570457994644658, 1.445305721320277,
                                     -0.5900435899266435};

/// Number of basis functions for a degree: (degree + 1)^2.
constexpr int NumSHBasis(int degree) { return (degree + 1) * (degree + 1); }

/// Writes the (degree+1)^2 basis values for a unit direction (x, y, z) into basis[0..].
template <typename T>
void EvaluateSHBasis(int degree, T x, T y, T z, T* basis) {
    basis[0] = T(kSH_C0);
    if (degree < 1) return;
    basis[1] = -T(kSH_C1) * y;
    basis[2] = T(kSH_C1) * z;
    basis[3] = -T(kSH_C1) * x;
    if (degree < 2) return;
    const T xx = x * x, yy = y * y, zz = z * z;
    const T xy = x * y, yz = y * z, xz = x * z;
    basis[4] = T(kSH_C2[0]) * xy;
    basis[5] = T(kSH_C2[1]) * yz;
    basis[6] = T(kSH_C2[2]) * (T(2) * zz - xx - yy);
    basis[7] = T(kSH_C2[3]) * xz;
    basis[8] = T(kSH_C2[4]) * (xx - yy);
    if (degree < 3) return;
    basis[9] = T(kSH_C3[0]) * y * (T(3) * xx - yy);
    basis[10] = T(kSH_C3[1]) * xy * z;
    basis[11] = T(kSH_C3[2]) * y * (T(4) * zz - xx - yy);
    basis[12] = T(kSH_C3[3]) * z * (T(2) * zz - T(3) * xx - T(3) * yy);
    basis[13] = T(kSH_C3[4]) * x * (T(4) * zz - xx - yy);
    basis[14] = T(kSH_C3[5]) * z * (xx - yy);
    basis[15] = T(kSH_C3[6]) * x * (xx - T(3) * yy);
}

/// Sum of the SH bands for one splat (no +0.5 offset, no clamp): f_dc [3],
/// f_rest [Nc, 3] (may be null when degree == 0), direction (x, y, z) of unit length.
template <typename T>
std::array<T, 3> EvaluateSH(int degree, const float* f_dc, const float* f_rest, T x, T y, T z) {
    T basis[16];
    EvaluateSHBasis(degree, x, y, z, basis);
    std::array<T, 3> rgb{};
    for (int c = 0; c < 3; ++c) rgb[c] = basis[0] * T(f_dc[c]);
    for (int j = 1; j < NumSHBasis(degree); ++j) {
        for (int c = 0; c < 3; ++c) rgb[c] += basis[j] * T(f_rest[(j - 1) * 3 + c]);
    }
    return rgb;
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
