// The depths that order splats, computed bit for bit alike by the compute shaders and the
// CPU reference (both include this file; GaussianSplatContract.h includes it after defining
// OPEN3D_SHADER_FUNC / OPEN3D_SHADER_PRECISE and the bit casts). Two orders
// (RenderConfig::depth_order, docs/accuracy.md):
// - ReferenceViewDepth: the original 3DGS rasterizer's float32 view z, in the operation order
//   its CUDA build executes, so near-tied splats blend in its order (the default);
// - SortDepth: a camera-relative depth that stays accurate far from the origin, where the
//   original's own float32 z loses the order of near splats.
#ifndef OPEN3D_SHADERS_GAUSSIAN_SPLAT_SORT_DEPTH_H
#define OPEN3D_SHADERS_GAUSSIAN_SPLAT_SORT_DEPTH_H

#ifndef OPEN3D_SHADER_FUNC
#error "include shaders/GaussianSplatContract.h, which defines the shader/C++ macros first"
#endif

// ---- Camera-relative depth ----

// One coordinate of the camera-relative position (p - c_hi) - c_lo (GaussianViewParams):
// p - c_hi is exact when p is within a factor 2 of c_hi (Sterbenz), i.e. for everything
// near a camera far from the origin, and c_lo restores the centre's float32 rounding.
OPEN3D_SHADER_FUNC float CameraRelative(float p, float c_hi, float c_lo) {
    OPEN3D_SHADER_PRECISE float d = (p - c_hi) - c_lo;
    return d;
}

// The camera-relative view depth (DepthOrder::kCameraRelative): float32 with a fixed
// operation order, every product and sum rounded (`precise`: no fused multiply-add, no
// reordering), from row 2 of the float32 world-to-camera rotation and the camera-relative
// position (CameraRelative).
OPEN3D_SHADER_FUNC float SortDepth(float r0, float r1, float r2, float dx, float dy, float dz) {
    OPEN3D_SHADER_PRECISE float xy = r0 * dx + r1 * dy;
    OPEN3D_SHADER_PRECISE float d = xy + r2 * dz;
    return d;
}

// ---- The original rasterizer's depth ----
// Its preprocess takes p_view.z = m[2] x + m[6] y + m[10] z + m[14] (transformPoint4x3 on its
// column-major float32 world-to-view matrix m), which nvcc contracts into
// fma(m10, z, fma(m2, x, m6 * y)) + m14: two fused multiply-adds, each rounded once. GLSL's
// fma() need not be fused (Vulkan lets it round like a multiply followed by an add), so the
// fused operation is built from multiplications and additions, which Vulkan and C++ round
// correctly: exact products (Dekker), exact sums (Knuth) and one addition rounded to odd
// (Boldo and Melquiond, "Emulation of FMA and correctly rounded sums: proved algorithms using
// rounding to odd", IEEE Trans. Computers 57(4), 2008). tests/.../SortDepthTest.cpp checks it
// against std::fma on hard cases.

// The rounding error of a + b: a + b == s + TwoSumError(a, b, s) exactly, s = float(a + b).
OPEN3D_SHADER_FUNC float TwoSumError(float a, float b, float s) {
    OPEN3D_SHADER_PRECISE float bb = s - a;
    OPEN3D_SHADER_PRECISE float e = (a - (s - bb)) + (b - bb);
    return e;
}

// The high half of a (12 significant bits) by Veltkamp's split; a - SplitHigh(a) is exact.
OPEN3D_SHADER_FUNC float SplitHigh(float a) {
    OPEN3D_SHADER_PRECISE float c = 4097.0f * a;  // 2^12 + 1
    OPEN3D_SHADER_PRECISE float high = c - (c - a);
    return high;
}

// The rounding error of a * b: a * b == p + TwoProductError(a, b, p) exactly, p = float(a * b),
// while |a b| stays inside the range where nothing over- or underflows (about 2^-100..2^100).
OPEN3D_SHADER_FUNC float TwoProductError(float a, float b, float p) {
    OPEN3D_SHADER_PRECISE float a_hi = SplitHigh(a);
    OPEN3D_SHADER_PRECISE float a_lo = a - a_hi;
    OPEN3D_SHADER_PRECISE float b_hi = SplitHigh(b);
    OPEN3D_SHADER_PRECISE float b_lo = b - b_hi;
    OPEN3D_SHADER_PRECISE float e = ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo;
    return e;
}

// a + b rounded to odd: the float next to the exact sum whose last significand bit is 1,
// unless the sum is exact. Together with a final round to nearest this avoids the double
// rounding of a sum of three terms.
OPEN3D_SHADER_FUNC float AddRoundToOdd(float a, float b) {
    OPEN3D_SHADER_PRECISE float s = a + b;
    float e = TwoSumError(a, b, s);
    uint bits = floatBitsToUint(s);
    if (e != 0.0f && (bits & 1u) == 0u) {
        // The exact sum lies between s and its neighbour on e's side: step the bit pattern
        // away from zero when e has s's sign, towards zero otherwise (s != 0 when e != 0).
        bool away = (e > 0.0f) == (s > 0.0f);
        bits = away ? bits + 1u : bits - 1u;
    }
    return uintBitsToFloat(bits);
}

// fma(a, b, c) rounded once, as a fused multiply-add does, while |a|, |b| <= 2^100 and
// 2^-60 <= |a b| <= 2^100: then no split overflows and every partial product is exact, even
// the smallest error term. Outside (zeros, non-finite values, depths far outside any view)
// it is a * b + c rounded twice, which equals the fused result for a zero product.
OPEN3D_SHADER_FUNC float ExactFma(float a, float b, float c) {
    OPEN3D_SHADER_PRECISE float p = a * b;
    float abs_a = a < 0.0f ? -a : a;
    float abs_b = b < 0.0f ? -b : b;
    float abs_p = p < 0.0f ? -p : p;
    const float kLargest = 1.2676506e30f;    // 2^100
    const float kSmallest = 8.6736174e-19f;  // 2^-60
    if (!(abs_a <= kLargest && abs_b <= kLargest && abs_p <= kLargest && abs_p >= kSmallest)) {
        OPEN3D_SHADER_PRECISE float plain = p + c;
        return plain;
    }
    float p_err = TwoProductError(a, b, p);
    OPEN3D_SHADER_PRECISE float t = c + p;
    float t_err = TwoSumError(c, p, t);
    float v = AddRoundToOdd(t_err, p_err);
    OPEN3D_SHADER_PRECISE float r = t + v;
    return r;
}

// The original rasterizer's view z of world position (x, y, z): m2, m6, m10, m14 are row 2 of
// its float32 world-to-view matrix [R | t] (R(2, 0), R(2, 1), R(2, 2), t_z, each rounded to
// float32 from the double camera; GaussianViewParams::reference_depth_row).
OPEN3D_SHADER_FUNC float ReferenceViewDepth(float m2, float m6, float m10, float m14, float x,
                                            float y, float z) {
    OPEN3D_SHADER_PRECISE float m6y = m6 * y;
    float xy = ExactFma(m2, x, m6y);
    float xyz = ExactFma(m10, z, xy);
    OPEN3D_SHADER_PRECISE float d = xyz + m14;
    return d;
}

#endif  // OPEN3D_SHADERS_GAUSSIAN_SPLAT_SORT_DEPTH_H
