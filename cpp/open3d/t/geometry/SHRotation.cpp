#include "open3d/t/geometry/SHRotation.h"

#include <cmath>

#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"

namespace open3d {
namespace t {
namespace geometry {

namespace {

// A square band matrix indexed by (m, n) in [-l, l], as the recursion is written.
struct BandMatrix {
    int l = 0;
    std::array<double, 49> values{};
    double& operator()(int m, int n) { return values[(m + l) * 7 + (n + l)]; }
    double operator()(int m, int n) const { return values[(m + l) * 7 + (n + l)]; }
};

// Ivanic-Ruedenberg helper P^l_{i,a,b} (Table 2 of the paper): couples the degree-1 matrix
// r1 with the previous band prev (degree l - 1).
double IrP(int i, int l, int a, int b, const BandMatrix& r1, const BandMatrix& prev) {
    if (b == l) return r1(i, 1) * prev(a, l - 1) - r1(i, -1) * prev(a, -l + 1);
    if (b == -l) return r1(i, 1) * prev(a, -l + 1) + r1(i, -1) * prev(a, l - 1);
    return r1(i, 0) * prev(a, b);
}

// One element of band l from the u, v, w weights (Table 1) and U, V, W terms (Table 2),
// with the signs of the 1998 erratum in the m < 0 branches of V and W.
double IrElement(int l, int m, int n, const BandMatrix& r1, const BandMatrix& prev) {
    const int abs_m = std::abs(m);
    const double d = m == 0 ? 1.0 : 0.0;
    const double denom =
        std::abs(n) < l ? double((l + n) * (l - n)) : double((2 * l) * (2 * l - 1));
    const double u = std::sqrt(double((l + m) * (l - m)) / denom);
    const double v = 0.5 * std::sqrt((1.0 + d) * double((l + abs_m - 1) * (l + abs_m)) / denom) *
                     (1.0 - 2.0 * d);
    const double w = -0.5 * std::sqrt(double((l - abs_m - 1) * (l - abs_m)) / denom) * (1.0 - d);

    double value = 0.0;
    if (u != 0.0) value += u * IrP(0, l, m, n, r1, prev);
    if (v != 0.0) {
        double big_v;
        if (m == 0) {
            big_v = IrP(1, l, 1, n, r1, prev) + IrP(-1, l, -1, n, r1, prev);
        } else if (m > 0) {
            const double d1 = m == 1 ? 1.0 : 0.0;
            big_v = IrP(1, l, m - 1, n, r1, prev) * std::sqrt(1.0 + d1) -
                    IrP(-1, l, -m + 1, n, r1, prev) * (1.0 - d1);
        } else {
            const double d1 = m == -1 ? 1.0 : 0.0;
            big_v = IrP(1, l, m + 1, n, r1, prev) * (1.0 - d1) +
                    IrP(-1, l, -m - 1, n, r1, prev) * std::sqrt(1.0 + d1);
        }
        value += v * big_v;
    }
    if (w != 0.0) {
        // w vanishes for m == 0, so only m != 0 reaches here.
        const double big_w = m > 0
                                 ? IrP(1, l, m + 1, n, r1, prev) + IrP(-1, l, -m - 1, n, r1, prev)
                                 : IrP(1, l, m - 1, n, r1, prev) - IrP(-1, l, -m + 1, n, r1, prev);
        value += w * big_w;
    }
    return value;
}

// Rotates the 2L+1 coefficients (x RGB) of one band in place; fixed sizes let the
// compiler unroll the small matrix product.
template <int L>
void RotateBand(const double* band, float* block) {
    constexpr int n = 2 * L + 1;
    double in[n][3];
    for (int j = 0; j < n; ++j) {
        for (int c = 0; c < 3; ++c) in[j][c] = block[j * 3 + c];
    }
    for (int i = 0; i < n; ++i) {
        double acc[3] = {0.0, 0.0, 0.0};
        for (int j = 0; j < n; ++j) {
            const double b = band[i * n + j];
            for (int c = 0; c < 3; ++c) acc[c] += b * in[j][c];
        }
        for (int c = 0; c < 3; ++c) block[i * 3 + c] = static_cast<float>(acc[c]);
    }
}

}  // namespace

SHRotation::SHRotation(const Eigen::Matrix3d& R, int degree) : degree_(degree) {
    if (degree < 0 || degree > kMaxSHRotationDegree) {
        core::ThrowError("SH rotation supports degree 0..{}, got {}", kMaxSHRotationDegree, degree);
    }
    is_identity_ = R == Eigen::Matrix3d::Identity();
    if (degree == 0) return;

    // Degree 1 of the unsigned real basis is (y, z, x) for m = -1, 0, +1, so its band
    // matrix is R with rows and columns permuted to that order.
    constexpr int kCartesian[3] = {1, 2, 0};  // m = -1, 0, +1 -> y, z, x
    BandMatrix r1;
    r1.l = 1;
    for (int m = -1; m <= 1; ++m) {
        for (int n = -1; n <= 1; ++n) r1(m, n) = R(kCartesian[m + 1], kCartesian[n + 1]);
    }

    BandMatrix prev = r1;
    for (int l = 1; l <= degree; ++l) {
        BandMatrix cur;
        if (l == 1) {
            cur = r1;
        } else {
            cur.l = l;
            for (int m = -l; m <= l; ++m) {
                for (int n = -l; n <= l; ++n) cur(m, n) = IrElement(l, m, n, r1, prev);
            }
        }
        // Our basis (SphericalHarmonics.h) is the unsigned one times (-1)^m per function
        // (Condon-Shortley phase), so its band matrix is S M S with S = diag((-1)^m).
        const int size = 2 * l + 1;
        double* out = bands_.data() + kBandOffset[l];
        for (int m = -l; m <= l; ++m) {
            for (int n = -l; n <= l; ++n) {
                const bool flip = ((m + n) & 1) != 0;
                out[(m + l) * size + (n + l)] = flip ? -cur(m, n) : cur(m, n);
            }
        }
        prev = cur;
    }
}

Eigen::MatrixXd SHRotation::GetBand(int l) const {
    if (l < 1 || l > degree_) {
        core::ThrowError("SH rotation band {} is out of range 1..{}", l, degree_);
    }
    const int size = 2 * l + 1;
    Eigen::MatrixXd band(size, size);
    for (int i = 0; i < size; ++i) {
        for (int j = 0; j < size; ++j) band(i, j) = bands_[kBandOffset[l] + i * size + j];
    }
    return band;
}

void SHRotation::Apply(float* f_rest) const {
    // The identity must leave stored data bit-exact (signed zeros, NaN payloads included),
    // which a product with an identity matrix does not promise.
    if (is_identity_) return;
    if (degree_ >= 1) RotateBand<1>(bands_.data() + kBandOffset[1], f_rest);
    if (degree_ >= 2) RotateBand<2>(bands_.data() + kBandOffset[2], f_rest + 3 * 3);
    if (degree_ >= 3) RotateBand<3>(bands_.data() + kBandOffset[3], f_rest + 8 * 3);
}

void RotateSHRest(const SHRotation& rotation, int64_t num_splats, float* f_rest) {
    const int degree = rotation.GetDegree();
    if (degree == 0 || rotation.IsIdentity() || num_splats <= 0) return;
    const int64_t stride = int64_t((degree + 1) * (degree + 1) - 1) * 3;
    core::ParallelFor(num_splats, [&](int64_t i) { rotation.Apply(f_rest + i * stride); });
}

void ApplySHParity(int degree, int64_t num_splats, float* f_rest) {
    if (degree < 0 || degree > kMaxSHRotationDegree) {
        core::ThrowError("SH parity supports degree 0..{}, got {}", kMaxSHRotationDegree, degree);
    }
    if (degree == 0 || num_splats <= 0) return;
    const int num_coeffs = (degree + 1) * (degree + 1) - 1;
    core::ParallelFor(num_splats, [&](int64_t i) {
        float* block = f_rest + i * num_coeffs * 3;
        // Band 1 is coefficients 0..2, band 3 is 8..14 (k = l^2 + l + m - 1).
        for (int k = 0; k < 3 * 3; ++k) block[k] = -block[k];
        if (degree >= 3) {
            for (int k = 8 * 3; k < 15 * 3; ++k) block[k] = -block[k];
        }
    });
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
