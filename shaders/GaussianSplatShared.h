// What the CPU reference and the compute shaders must compute bit for bit alike, and nothing
// else: the tile grid and tile culling, the camera-centre split and the sort depths. GLSL
// (through GaussianSplatCommon.h) and C++ (namespace ...::rendering::shader); no buffer
// layout, binding or packing, so the CPU reference includes it without the GPU contract.
// `precise` (GLSL) and -ffp-contract=off (C++) round every operation where the source says.
// It defines the language macros (OPEN3D_SHADER_CONST/FUNC/PRECISE) every shader header uses.
#ifndef OPEN3D_SHADERS_GAUSSIAN_SPLAT_SHARED_H
#define OPEN3D_SHADERS_GAUSSIAN_SPLAT_SHARED_H

#ifdef __cplusplus
#include <bit>
#include <cmath>
#include <cstdint>

namespace open3d {
namespace visualization {
namespace rendering {
namespace shader {

using uint = uint32_t;
struct alignas(16) vec4 {  // GLSL's vec4 (EllipseBandReach returns one)
    // Constructors, not aggregate initialisation: clang 14 (the fuzz build) does not take
    // C++20's parenthesised aggregate initialisation that GLSL-style `vec4(a, b, c, d)` needs.
    vec4() = default;
    constexpr vec4(float x_, float y_, float z_, float w_) : x(x_), y(y_), z(z_), w(w_) {}
    float x, y, z, w;
};
inline uint floatBitsToUint(float value) { return std::bit_cast<uint>(value); }
inline float uintBitsToFloat(uint value) { return std::bit_cast<float>(value); }
using std::ceil;
using std::floor;
using std::log;
using std::sqrt;
#define OPEN3D_SHADER_CONST inline constexpr
#define OPEN3D_SHADER_FUNC inline
#define OPEN3D_SHADER_PRECISE
#else
#define OPEN3D_SHADER_CONST const
#define OPEN3D_SHADER_FUNC
#define OPEN3D_SHADER_PRECISE precise
#endif

// ---- Tile grid ----
// Side of the square screen tiles in pixels (== RenderConfig.h kTileSize, asserted in C++).
OPEN3D_SHADER_CONST uint kGaussianTileSize = 16u;
// Bound of a splat's 3-sigma radius (pixels): ceil(3 sqrt(lambda)) can pass 2^32 (a 1e4-scale
// splat by a telephoto camera), where float-to-int is undefined; clamped, a splat within
// ~1e9 px of the image still covers the whole grid (<= 65535 tiles per axis) as it would.
OPEN3D_SHADER_CONST uint kMaxSplatRadius = 1073741824u;  // 2^30, exact in float32

// Tiles along an image axis of `pixels` pixels.
OPEN3D_SHADER_FUNC uint TilesForPixels(uint pixels) { return (pixels + 15u) / kGaussianTileSize; }

// ---- Camera-relative position ----
// One coordinate of (p - c_hi) - c_lo: p - c_hi is exact for p within a factor 2 of c_hi
// (Sterbenz), and c_lo restores the float32 rounding of a camera centre far from the origin.
OPEN3D_SHADER_FUNC float CameraRelative(float p, float c_hi, float c_lo) {
    OPEN3D_SHADER_PRECISE float d = (p - c_hi) - c_lo;
    return d;
}
#ifdef __cplusplus
// The camera centre c as float32 high = float(c) plus low = float(c - high) (c_hi, c_lo).
struct CameraCenterSplit {
    float high[3] = {0.f, 0.f, 0.f};
    float low[3] = {0.f, 0.f, 0.f};
};
inline CameraCenterSplit SplitCameraCenter(const double center[3]) {
    CameraCenterSplit split;
    for (int i = 0; i < 3; ++i) {
        // volatile: GCC 12.2 -O2 folds c - double(float(c)) to 0 here for i = 1, 2.
        volatile float high = static_cast<float>(center[i]);
        split.high[i] = high;
        split.low[i] = static_cast<float>(center[i] - double(high));
    }
    return split;
}
#endif

// ---- Sort depths (RenderConfig::depth_order, docs/accuracy.md) ----
// SortDepth (DepthOrder::kCameraRelative): row 2 of the float32 rotation times the
// camera-relative position, every product and sum rounded; accurate far from the origin.
OPEN3D_SHADER_FUNC float SortDepth(float r0, float r1, float r2, float dx, float dy, float dz) {
    OPEN3D_SHADER_PRECISE float xy = r0 * dx + r1 * dy;
    OPEN3D_SHADER_PRECISE float d = xy + r2 * dz;
    return d;
}

// The original's p_view.z = m[2] x + m[6] y + m[10] z + m[14] (column-major float32 matrix
// m) is what nvcc contracts into fma(m10, z, fma(m2, x, m6 * y)) + m14. GLSL's fma() need not
// be fused, so ExactFma builds the fused result from correctly rounded operations: exact
// products (Dekker), exact sums (Knuth) and one addition rounded to odd (Boldo and Melquiond,
// IEEE Trans. Computers 57(4), 2008). SortDepthTest.cpp checks it against std::fma.
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
// while nothing over- or underflows (|a b| about 2^-100..2^100).
OPEN3D_SHADER_FUNC float TwoProductError(float a, float b, float p) {
    OPEN3D_SHADER_PRECISE float a_hi = SplitHigh(a);
    OPEN3D_SHADER_PRECISE float a_lo = a - a_hi;
    OPEN3D_SHADER_PRECISE float b_hi = SplitHigh(b);
    OPEN3D_SHADER_PRECISE float b_lo = b - b_hi;
    OPEN3D_SHADER_PRECISE float e = ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo;
    return e;
}

// a + b rounded to odd (last significand bit 1 unless exact): with a final round to nearest
// this avoids the double rounding of a sum of three terms.
OPEN3D_SHADER_FUNC float AddRoundToOdd(float a, float b) {
    OPEN3D_SHADER_PRECISE float s = a + b;
    float e = TwoSumError(a, b, s);
    uint bits = floatBitsToUint(s);
    if (e != 0.0f && (bits & 1u) == 0u) {
        // Step towards the exact sum: away from zero when e has s's sign (s != 0 here).
        bool away = (e > 0.0f) == (s > 0.0f);
        bits = away ? bits + 1u : bits - 1u;
    }
    return uintBitsToFloat(bits);
}

// fma(a, b, c) rounded once while |a|, |b| <= 2^100 and 2^-60 <= |a b| <= 2^100 (no split
// overflows, every partial product exact). Outside (zeros, non-finite values, depths far
// outside any view) a * b + c rounded twice, the fused result for a zero product.
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

// The original rasterizer's view z of world position (x, y, z) (DepthOrder::kReference, the
// default): m2, m6, m10, m14 = row 2 of its float32 world-to-view matrix [R | t].
OPEN3D_SHADER_FUNC float ReferenceViewDepth(float m2, float m6, float m10, float m14, float x,
                                            float y, float z) {
    OPEN3D_SHADER_PRECISE float m6y = m6 * y;
    float xy = ExactFma(m2, x, m6y);
    float xyz = ExactFma(m10, z, xy);
    OPEN3D_SHADER_PRECISE float d = xyz + m14;
    return d;
}
#ifdef __cplusplus
// m2, m6, m10, m14 of ReferenceViewDepth: R(2, 0..2) and t_z, each rounded from double
// (what the CPU reference and GaussianViewParams::reference_depth_row hold).
struct ReferenceDepthRow {
    float m2 = 0.f, m6 = 0.f, m10 = 0.f, m14 = 0.f;
};
#endif

// ---- Tile culling: which tiles of the 3DGS rectangle a splat can change ----
// The composite skips a splat where alpha = o exp(-q / 2) < 1/255 (q = a dx^2 + 2 b dx dy +
// c dy^2), so only tiles that meet the ellipse q <= 2 ln(255 o) get entries; every image stays
// bit for bit what the full rectangle gives (docs/vulkan.md "Tile culling").

// The threshold on q, widened so that rounding cannot cull a tile the composite blends into:
// +1% (+0.01), plus 4e-4 (1 + t) a c / det_q, 40x the composite's own float32 rounding of q
// (about 8 eps q / (1 - |rho|) <= 1.1e-5 q a c / det_q). det_q = a c - b^2 = 1 / det(cov).
// <= 0 (opacity below 1/255): no pixel reaches the blending threshold.
OPEN3D_SHADER_FUNC float TileCullThreshold(float opacity, float a, float c, float det_q) {
    OPEN3D_SHADER_PRECISE float t = 2.0f * log(255.0f * opacity);
    OPEN3D_SHADER_PRECISE float slack = 1.0f + (t > 0.0f ? t : 0.0f);
    OPEN3D_SHADER_PRECISE float margin = slack * (0.01f + 4e-4f * (a * c / det_q));
    OPEN3D_SHADER_PRECISE float widened = t + margin;
    return widened;
}

// Where the ellipse q <= t reaches within the band of row offsets [lo, hi] from the centre:
// x offsets (x_l, x_r, margin to widen both by, 1); w = 0 when the band misses it. x_ext,
// y_ext = sqrt(c t / det_q), sqrt(a t / det_q), finite. The right edge x_r(dy) is concave with
// its peak at dy* = -b sqrt(t / (det_q c)), so its band maximum is at dy* clamped to the band
// (the left edge mirrors it); widened by 0.5 px + 1/256 of the extent for own rounding.
OPEN3D_SHADER_FUNC vec4 EllipseBandReach(float a, float b, float c, float det_q, float t,
                                         float x_ext, float y_ext, float lo, float hi) {
    vec4 band;
    band.x = band.y = band.z = band.w = 0.0f;
    OPEN3D_SHADER_PRECISE float reach = y_ext * (1.0f + 1.0f / 256.0f) + 0.5f;
    lo = lo > -reach ? lo : -reach;
    hi = hi < reach ? hi : reach;
    if (!(lo <= hi)) return band;
    OPEN3D_SHADER_PRECISE float peak = -b * (x_ext / c);
    OPEN3D_SHADER_PRECISE float dy_r = peak < lo ? lo : (peak > hi ? hi : peak);
    OPEN3D_SHADER_PRECISE float dy_l = -peak < lo ? lo : (-peak > hi ? hi : -peak);
    OPEN3D_SHADER_PRECISE float s_r = a * t - det_q * (dy_r * dy_r);
    OPEN3D_SHADER_PRECISE float s_l = a * t - det_q * (dy_l * dy_l);
    OPEN3D_SHADER_PRECISE float x_r = (sqrt(s_r > 0.0f ? s_r : 0.0f) - b * dy_r) / a;
    OPEN3D_SHADER_PRECISE float x_l = (-sqrt(s_l > 0.0f ? s_l : 0.0f) - b * dy_l) / a;
    OPEN3D_SHADER_PRECISE float margin = 0.5f + x_ext * (1.0f / 256.0f);
    band.x = x_l;
    band.y = x_r;
    band.z = margin;
    band.w = 1.0f;
    return band;
}

// Tile columns [first, last) of tile row `ty` that the ellipse q <= t of a splat centred at
// (cx, cy) touches within the rectangle's columns [rect_x0, rect_x1), as first | last << 16
// (empty: first == last == rect_x0). Row ty covers pixel rows 16 ty .. 16 ty + 15 (pixels
// evaluated at integer positions); anything not finite gives the whole rectangle row.
OPEN3D_SHADER_FUNC uint TileRowSpan(float cx, float cy, float a, float b, float c, float det_q,
                                    float t, uint ty, uint rect_x0, uint rect_x1) {
    uint whole = rect_x0 | (rect_x1 << 16u);
    uint none = rect_x0 | (rect_x0 << 16u);
    if (!(t > 0.0f)) return none;
    OPEN3D_SHADER_PRECISE float y_ext = sqrt(a * t / det_q);
    OPEN3D_SHADER_PRECISE float x_ext = sqrt(c * t / det_q);
    if (!(y_ext < 1e30f && x_ext < 1e30f && a > 0.0f && c > 0.0f)) return whole;
    OPEN3D_SHADER_PRECISE float lo = float(ty * kGaussianTileSize) - cy;
    OPEN3D_SHADER_PRECISE float hi = lo + float(kGaussianTileSize - 1u);
    vec4 band = EllipseBandReach(a, b, c, det_q, t, x_ext, y_ext, lo, hi);
    if (band.w == 0.0f) return none;
    OPEN3D_SHADER_PRECISE float first = ceil((cx + band.x - band.z - 15.0f) / 16.0f);
    OPEN3D_SHADER_PRECISE float last = floor((cx + band.y + band.z) / 16.0f) + 1.0f;
    if (!(first <= last || first > last)) return whole;  // NaN
    first = first > float(rect_x0) ? first : float(rect_x0);
    first = first < float(rect_x1) ? first : float(rect_x1);
    last = last > first ? last : first;
    last = last < float(rect_x1) ? last : float(rect_x1);
    return uint(first) | (uint(last) << 16u);
}

// Tiles of a span from TileRowSpan.
OPEN3D_SHADER_FUNC uint TileSpanCount(uint span) { return (span >> 16u) - (span & 0xFFFFu); }

#ifdef __cplusplus
}  // namespace shader
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
#endif  // __cplusplus
#endif  // OPEN3D_SHADERS_GAUSSIAN_SPLAT_SHARED_H
