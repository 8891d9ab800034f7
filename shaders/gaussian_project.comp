#version 460
// Geometry stage, pass 1: one invocation per splat. Exactly the 3DGS rasterizer's preprocess
// (docs/DESIGN.md "Numerical rules", mirrored from cpu/Projection.cpp) in float32: near cull,
// guard-band clamped Jacobian, +0.3 dilation, optional antialias compensation, det == 0
// cull, 3-sigma radius with the 0.1 eigenvalue floor, tile rectangle, SH colour. Visible
// splats write their GaussianProjectedSplat and append (depth key, splat index) to the
// visible list with one atomicAdd per subgroup.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_EXT_control_flow_attributes : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#include "GaussianSplatTileListContract.h"
#include "gaussian_device_address.glsl"

layout(local_size_x = kProjectWorkgroupSize) in;

// Specialisation: a degree-0 scene never touches the SH binding; antialias off skips the
// compensation; the precision picks how the shape and SH words decode.
layout(constant_id = kSpecShDegree) const uint kShDegree = 3u;
layout(constant_id = kSpecAntialias) const uint kAntialias = 0u;
layout(constant_id = kSpecPrecision) const uint kPrecision = kPrecisionExact;
layout(constant_id = kSpecIndexedList) const uint kIndexedList = 1u;
layout(constant_id = kSpecCutList) const uint kCutList = 0u;
layout(constant_id = kSpecBinTiles) const uint kBinTiles = 0u;
layout(constant_id = kSpecDepthDigits) const uint kDepthDigits = 0u;

layout(std430, set = 0, binding = kGeometryStageViewBinding) readonly buffer ViewBlock {
    GaussianViewParams view;
};
// The positions (xyz, sigmoid(opacity)) and the shape and SH words through their device
// addresses, as uint, uvec2 and uvec4: a warp's scalar loads at a 40- or 96-byte stride touch
// 32 sectors per instruction, so the aligned layouts are read in wider loads.
layout(push_constant, std430) uniform AddressesBlock {
    layout(offset = kGeometryAddressesPushOffset) GaussianGeometryAddresses addresses;
};
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Words {
    uint words[];
};
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer Words2 {
    uvec2 words[];
};
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Words4 {
    uvec4 words[];
};
// Bits by splat, or with kCutList the level-of-detail cut's nodes by slot.
layout(std430, set = 0, binding = kGeometryStageVisibilityBinding) readonly buffer VisibilityBlock {
    uint visibility[];
};
layout(std430, set = 0, binding = kGeometryStageCountersBinding) buffer CountersBlock {
    GaussianGeometryStageCounters counters;
};
layout(std430, set = 0, binding = kGeometryStageDepthKeysBinding) writeonly buffer DepthKeysBlock {
    uint depth_keys[];
};
layout(std430, set = 0, binding = kGeometryStageSplatIndexBinding) writeonly buffer SplatIndexBlock {
    uint splat_indices[];
};
// The scan gathers these 4 bytes per visible splat in depth order: a dense array stays in
// the GPU's L2 cache where a field of the 64-byte projected records did not.
layout(std430, set = 0, binding = kGeometryStageTileCountsBinding) writeonly buffer TileCountsBlock {
    uint tile_counts[];
};

// Per-tile bins: word kBinRangesWordOffset + 2 t + 1 counts tile t's entries (zeroed by the
// recorder).
layout(std430, set = 0, binding = kGeometryStageTileRangesBinding) buffer TileRangesBlock {
    uint tile_bins[];
};

// kDepthDigits: the depth sort's one-sweep histogram, its parameters (written by the
// recorder: the block count) and its look-back status words.
layout(std430, set = 0, binding = kGeometryStageDepthSortStateBinding) buffer DepthSortStateBlock {
    RadixSweepState depth_sort_state;
};
layout(std430, set = 0, binding = kGeometryStageSortParamsBinding) readonly buffer SortParamsBlock {
    RadixSortParams depth_sort_params;
};
layout(std430, set = 0, binding = kGeometryStageSortStatusBinding) writeonly buffer SortStatusBlock {
    uint sort_status[];
};
// This workgroup's digit counts of its visible depth keys, pass-major (kDepthDigits only).
shared uint s_depth_digits[kRadixSortMaxPasses * kRadixSortBins];

const float kSH_C0 = 0.28209479177387814;
const float kSH_C1 = 0.4886025119029199;
const float kSH_C2[5] = float[5](1.0925484305920792, -1.0925484305920792, 0.31539156525252005,
                                 -1.0925484305920792, 0.5462742152960396);
const float kSH_C3[7] = float[7](-0.5900435899266435, 2.890611442640554, -0.4570457994644658,
                                 0.3731763325901154, -0.4570457994644658, 1.445305721320277,
                                 -0.5900435899266435);

uint64_t ShapeRecord(uint i, uint words_per_splat) {
    return RecordAddress(DeviceAddress(addresses.shape_lo, addresses.shape_hi), i,
                         words_per_splat * 4u);
}

uint64_t ShRecord(uint i, uint words_per_splat) {
    return RecordAddress(DeviceAddress(addresses.sh_lo, addresses.sh_hi), i, words_per_splat * 4u);
}

// Half k of the compact record at `record` (halves k and k + 1 share a word).
float HalfAt(uint64_t record, uint k) {
    vec2 pair = unpackHalf2x16(Words(record).words[k / 2u]);
    return (k & 1u) == 0u ? pair.x : pair.y;
}

// The exact shape words of the splat being projected, loaded by LoadShape in five uvec2
// loads (its 40-byte records are 8-byte aligned).
float g_shape[kShapeWordsExact];

void LoadShape(uint i) {
    if (kPrecision == kPrecisionCompact) return;
    Words2 record = Words2(ShapeRecord(i, kShapeWordsExact));
    [[unroll]] for (uint q = 0u; q < kShapeWordsExact / 2u; ++q) {
        uvec2 w = record.words[q];
        g_shape[2u * q] = uintBitsToFloat(w.x);
        g_shape[2u * q + 1u] = uintBitsToFloat(w.y);
    }
}

// Shape value k (0-2 scale, 3-6 rotation wxyz, 7-9 f_dc) of splat i.
float ShapeValue(uint i, uint k) {
    if (kPrecision == kPrecisionCompact) return HalfAt(ShapeRecord(i, kShapeWordsCompact), k);
    return g_shape[k];
}

// SH rest coefficient j (1-based basis index), channel c of splat i; layout [Nc, 3].
float ShValue(uint i, uint j, uint c) {
    uint k = (j - 1u) * 3u + c;
    uint64_t record = ShRecord(i, view.sh_words_per_splat);
    if (kPrecision == kPrecisionCompact) return HalfAt(record, k);
    return uintBitsToFloat(Words(record).words[k]);
}

// M = R diag(s) (the 3D covariance is M M^T) for a (w, x, y, z) quaternion normalised at
// packing; the formula is the one Eigen's toRotationMatrix uses, so a zero quaternion gives
// the identity as on the CPU.
mat3 CovarianceFactor(vec3 s, vec4 q) {
    float tx = 2.0 * q.y, ty = 2.0 * q.z, tz = 2.0 * q.w;
    float twx = tx * q.x, twy = ty * q.x, twz = tz * q.x;
    float txx = tx * q.y, txy = ty * q.y, txz = tz * q.y;
    float tyy = ty * q.z, tyz = tz * q.z, tzz = tz * q.w;
    // Column-major constructor: r[col][row].
    mat3 r = mat3(1.0 - (tyy + tzz), txy + twz, txz - twy,  // column 0
                  txy - twz, 1.0 - (txx + tzz), tyz + twx,  // column 1
                  txz + twy, tyz - twx, 1.0 - (txx + tyy));  // column 2
    return r * mat3(s.x, 0.0, 0.0, 0.0, s.y, 0.0, 0.0, 0.0, s.z);
}

// f_rest words of the evaluated degree; the fast path below needs whole uvec4s of them.
const uint kShWords = 3u * ((kShDegree + 1u) * (kShDegree + 1u) - 1u);
const uint kShVec4s = kShWords / 4u;
// A product, not an && chain: glslang 12 (Debian 12) turns && of spec constants into a phi
// that the OpSpecConstantOp then names before it exists (invalid SPIR-V,
// docs/environment-notes.md).
const uint kShVec4Layout = uint(kPrecision == kPrecisionExact) * uint(kShWords % 4u == 0u) *
                           uint(kShWords > 0u);

// `relative`: the camera-relative position (never 0: the splat passed the near plane).
vec3 ShColor(uint i, vec3 relative) {
    vec3 dc = vec3(ShapeValue(i, 7u), ShapeValue(i, 8u), ShapeValue(i, 9u));
    bool vec4_path = kShVec4Layout != 0u;
    if (view.sh_words_per_splat != kShWords) vec4_path = false;  // packed at another degree
    vec3 rgb = kSH_C0 * dc;
    if (kShDegree >= 1u) {
        vec3 d = normalize(relative);
        float x = d.x, y = d.y, z = d.z;
        float basis[16];
        basis[1] = -kSH_C1 * y;
        basis[2] = kSH_C1 * z;
        basis[3] = -kSH_C1 * x;
        if (kShDegree >= 2u) {
            float xx = x * x, yy = y * y, zz = z * z;
            float xy = x * y, yz = y * z, xz = x * z;
            basis[4] = kSH_C2[0] * xy;
            basis[5] = kSH_C2[1] * yz;
            basis[6] = kSH_C2[2] * (2.0 * zz - xx - yy);
            basis[7] = kSH_C2[3] * xz;
            basis[8] = kSH_C2[4] * (xx - yy);
            if (kShDegree >= 3u) {
                basis[9] = kSH_C3[0] * y * (3.0 * xx - yy);
                basis[10] = kSH_C3[1] * xy * z;
                basis[11] = kSH_C3[2] * y * (4.0 * zz - xx - yy);
                basis[12] = kSH_C3[3] * z * (2.0 * zz - 3.0 * xx - 3.0 * yy);
                basis[13] = kSH_C3[4] * x * (4.0 * zz - xx - yy);
                basis[14] = kSH_C3[5] * z * (xx - yy);
                basis[15] = kSH_C3[6] * x * (xx - 3.0 * yy);
            }
        }
        uint num_basis = (kShDegree + 1u) * (kShDegree + 1u);
        if (vec4_path) {
            float words[48];  // f_rest words of degree 3, rounded up to uvec4s
            Words4 record = Words4(ShRecord(i, kShWords));
            [[unroll]] for (uint q = 0u; q < kShVec4s; ++q) {
                uvec4 w = record.words[q];
                words[4u * q] = uintBitsToFloat(w.x);
                words[4u * q + 1u] = uintBitsToFloat(w.y);
                words[4u * q + 2u] = uintBitsToFloat(w.z);
                words[4u * q + 3u] = uintBitsToFloat(w.w);
            }
            [[unroll]] for (uint j = 1u; j < num_basis; ++j) {
                uint k = (j - 1u) * 3u;
                rgb += basis[j] * vec3(words[k], words[k + 1u], words[k + 2u]);
            }
        } else {
            for (uint j = 1u; j < num_basis; ++j) {
                rgb += basis[j] * vec3(ShValue(i, j, 0u), ShValue(i, j, 1u), ShValue(i, j, 2u));
            }
        }
    }
    return max(vec3(0.0), 0.5 + rgb);
}

// 3DGS getRect for one bound: (int)(v / 16) clamped to [0, tiles]; the float is clamped
// before the conversion so huge or non-finite values cannot overflow it.
uint TileBound(float v, uint tiles) {
    float t = v / float(kGaussianTileSize);
    if (!(t > 0.0)) return 0u;
    return uint(min(t, float(tiles)));
}

// Returns true (and writes the record of slot `slot`) when splat i is visible.
bool Project(uint i, uint slot, out float depth, out uint entries) {
    depth = 0.0;
    if (kCutList == 0u && (visibility[i >> 5u] & (1u << (i & 31u))) == 0u) return false;
    vec4 position_opacity = uintBitsToFloat(
        Words4(RecordAddress(DeviceAddress(addresses.positions_lo, addresses.positions_hi), i, 16u))
            .words[0]);
    vec3 p = position_opacity.xyz;
    // Camera-relative (p - c_hi) - c_lo: precise 1e5 from the origin too (GaussianSplatShared.h).
    vec3 c_hi = view.center_high;
    vec3 c_lo = vec3(view.center_low_x, view.center_low_y, view.center_low_z);
    vec3 rel = vec3(CameraRelative(p.x, c_hi.x, c_lo.x), CameraRelative(p.y, c_hi.y, c_lo.y),
                    CameraRelative(p.z, c_hi.z, c_lo.z));
    vec3 r2 = view.rotation_row2;
    // The camera-relative view z: the projection, the composite's depth and depth images.
    float view_z = SortDepth(r2.x, r2.y, r2.z, rel.x, rel.y, rel.z);
    // The depth that orders the splat and culls it at the near plane, bit for bit the CPU
    // reference's: the original rasterizer's float32 z by default (GaussianSplatShared.h).
    float order_depth = view_z;
    if (view.depth_order == kDepthOrderReference) {
        order_depth = ReferenceViewDepth(view.reference_m2, view.reference_m6, view.reference_m10,
                                         view.reference_m14, p.x, p.y, p.z);
    }
    if (!(order_depth > view.near_plane)) return false;  // near plane (also NaN)
    LoadShape(i);
    vec3 v = vec3(dot(view.rotation_row0, rel), dot(view.rotation_row1, rel), view_z);
    float fx = view.fx, fy = view.fy;
    float px = fx * v.x / v.z + view.cx;
    float py = fy * v.y / v.z + view.cy;

    // Jacobian at the guard-band clamped position (keeps off-screen footprints bounded); the
    // band is centred on the image (on the axis for a centred principal point: -g .. g).
    float x_over_z = clamp(v.x / v.z, view.guard_center_x - view.guard_x,
                           view.guard_center_x + view.guard_x);
    float y_over_z = clamp(v.y / v.z, view.guard_center_y - view.guard_y,
                           view.guard_center_y + view.guard_y);
    float tx = x_over_z * v.z, ty = y_over_z * v.z;
    float z2 = v.z * v.z;
    // J's z column, -f tx / z^2 as the original computes it; past z ~ 1.8e19 z^2 overflows
    // float32 and that quotient drops to 0 while the term, times a splat as large as its
    // distance, is of pixel size: there -f (x / z) / z, the same value without the overflow.
    float jx = isinf(z2) ? -fx * x_over_z / v.z : -fx * tx / z2;
    float jy = isinf(z2) ? -fy * y_over_z / v.z : -fy * ty / z2;
    // Rows of J (2x3) times W (the world-to-camera rotation): T = J W.
    vec3 w0 = view.rotation_row0, w1 = view.rotation_row1, w2 = view.rotation_row2;
    vec3 t0 = (fx / v.z) * w0 + jx * w2;
    vec3 t1 = (fy / v.z) * w1 + jy * w2;
    vec3 scale = vec3(ShapeValue(i, 0u), ShapeValue(i, 1u), ShapeValue(i, 2u));
    vec4 rot = vec4(ShapeValue(i, 3u), ShapeValue(i, 4u), ShapeValue(i, 5u), ShapeValue(i, 6u));
    // cov2D = T M (T M)^T: rows u0 = M^T t0, u1 = M^T t1, and det(cov2D) = |u0 x u1|^2
    // (Lagrange's identity), which cannot cancel the way a c - b^2 does in float32 (a flat
    // splat seen edge-on is rank one: a c and b^2 agree to rounding, their difference is noise).
    mat3 m = CovarianceFactor(scale, rot);
    vec3 u0 = t0 * m, u1 = t1 * m;
    float cov_a = dot(u0, u0), cov_b = dot(u0, u1), cov_c = dot(u1, u1);
    vec3 u_cross = cross(u0, u1);
    float det_raw = dot(u_cross, u_cross);

    // Low-pass dilation, conic, antialias factor, 3-sigma radius (ComputeScreenEllipse with
    // det_raw): det(cov + 0.3 I) expanded, >= 0.09 unless not finite. A covariance past the
    // float range (an astronomically large splat: the determinant grows as the 4th power of
    // its screen size) is culled, as the CPU reference does (docs/accuracy.md "Extremes").
    float det = det_raw + 0.3 * (cov_a + cov_c) + 0.09;
    if (!(det > 0.0) || isinf(det)) return false;
    float half_diff = 0.5 * (cov_a - cov_c);
    cov_a += 0.3;
    cov_c += 0.3;
    float opacity_scale = 1.0;
    if (kAntialias != 0u) opacity_scale = sqrt(max(0.000025, det_raw / det));
    vec3 conic = vec3(cov_c / det, -cov_b / det, cov_a / det);
    float mid = 0.5 * (cov_a + cov_c);
    // mid^2 - det written as ((a - c) / 2)^2 + b^2: the same value without the cancellation.
    float lambda1 = mid + sqrt(max(0.1, half_diff * half_diff + cov_b * cov_b));
    // Clamped before the conversion, which is undefined past 2^32 (kMaxSplatRadius).
    uint radius = uint(min(ceil(3.0 * sqrt(lambda1)), float(kMaxSplatRadius)));

    uint tiles_x = view.tiles_x, tiles_y = view.tiles_y;
    float r = float(radius);
    uvec2 rect_min = uvec2(TileBound(px - r, tiles_x), TileBound(py - r, tiles_y));
    uvec2 rect_max = uvec2(TileBound(px + r + float(kGaussianTileSize - 1u), tiles_x),
                           TileBound(py + r + float(kGaussianTileSize - 1u), tiles_y));
    if (rect_max.x == rect_min.x || rect_max.y == rect_min.y) return false;

    // Tiles of the rectangle that the alpha >= 1/255 ellipse meets (TileRowSpan): the
    // entries this splat will emit. A visible splat may emit none (opacity < 1/255).
    float opacity = position_opacity.w * opacity_scale;
    float det_q = 1.0 / det;  // a c - b^2 of the conic, without its cancellation
    float cull_t = TileCullThreshold(opacity, conic.x, conic.z, det_q);
    uint num_tiles = 0u;
    for (uint ty = rect_min.y; ty < rect_max.y; ++ty) {
        num_tiles += TileSpanCount(TileRowSpan(px, py, conic.x, conic.y, conic.z, det_q, cull_t,
                                               ty, rect_min.x, rect_max.x));
    }

    // Per-tile bins: the same spans again, one count per tile the emit pass will fill. A
    // splat over max_tiles_per_splat emits nothing (the bin scan raises the flag).
    if (kBinTiles != 0u && num_tiles > view.max_tiles_per_splat) {
        atomicOr(counters.error_flags, kErrorEntriesDropped);
    } else if (kBinTiles != 0u && num_tiles > 0u) {
        bool whole_rect = num_tiles == (rect_max.x - rect_min.x) * (rect_max.y - rect_min.y);
        for (uint ty = rect_min.y; ty < rect_max.y; ++ty) {
            uint span = whole_rect ? rect_min.x | (rect_max.x << 16u)
                                   : TileRowSpan(px, py, conic.x, conic.y, conic.z, det_q,
                                                 cull_t, ty, rect_min.x, rect_max.x);
            for (uint tx = span & 0xFFFFu; tx < (span >> 16u); ++tx) {
                atomicAdd(tile_bins[kBinRangesWordOffset + 2u * (ty * tiles_x + tx) + 1u], 1u);
            }
        }
    }

    vec3 color = ShColor(i, rel);
    GaussianProjectedSplat out_splat;
    out_splat.center_x = px;
    out_splat.center_y = py;
    out_splat.depth = view_z;
    out_splat.opacity = opacity;
    out_splat.conic = conic;
    out_splat.cull_threshold = cull_t;
    out_splat.color = color;
    out_splat.det_q = det_q;
    out_splat.rect_min = rect_min.x | (rect_min.y << 16u);
    out_splat.rect_max = rect_max.x | (rect_max.y << 16u);
    out_splat.num_entries = num_tiles;
    out_splat.radius = radius;
    ProjectedOut(RecordAddress(DeviceAddress(addresses.projected_lo, addresses.projected_hi), slot,
                               kProjectedSplatBytes))
        .words = PackProjectedSplat(out_splat);
    tile_counts[slot] = num_tiles;
    depth = order_depth;
    entries = num_tiles;
    return true;
}

void main() {
    uint i = FlatWorkGroupIndex() * kProjectWorkgroupSize + gl_LocalInvocationIndex;
    if (kDepthDigits != 0u) {
        for (uint p = 0u; p < kRadixSortMaxPasses; ++p) {
            s_depth_digits[p * kRadixSortBins + gl_LocalInvocationIndex] = 0u;
        }
        barrier();
    }
    float depth = 0.0;
    uint entries = 0u;
    // Slot i holds splat i, or the cut's node list[i] (its slots past the cut's size are
    // empty: as hidden splats, they sort last).
    bool in_list = i < view.num_splats && (kCutList == 0u || i < counters.lod_cut_nodes);
    uint splat = kCutList != 0u && in_list ? visibility[i] : i;
    bool visible = in_list && Project(splat, i, depth, entries);
    uint value = PackListValue(i, entries, view.num_splats);

    // One atomicAdd per subgroup reserves the slots of all its visible splats.
    uint flag = visible ? 1u : 0u;
    uint subgroup_count = subgroupAdd(flag);
    uint rank = subgroupExclusiveAdd(flag);
    uint base = 0u;
    if (subgroupElect() && subgroup_count > 0u) {
        base = atomicAdd(counters.visible_count, subgroup_count);
    }
    base = subgroupBroadcastFirst(base);
    if (kIndexedList != 0u) {
        // Slot i = splat i; hidden or culled splats get the largest key and sort last.
        if (i < view.num_splats) {
            depth_keys[i] = visible ? floatBitsToUint(depth) : 0xFFFFFFFFu;
            splat_indices[i] = value;
        }
    } else if (visible) {
        // depth > near plane > 0, so the float bits order like the depths.
        depth_keys[base + rank] = floatBitsToUint(depth);
        splat_indices[base + rank] = value;
    }
    if (kDepthDigits != 0u) {
        // What radix_sort_sweep_histogram.comp would do for the depth sort's kept keys (the
        // visible ones; 32 bits, four passes): count every digit, one atomic per non-zero bin
        // and workgroup, and zero the first pass's status row of block FlatWorkGroupIndex()
        // (the sort's blocks hold at least a workgroup's worth of slots, so every block has
        // a projection workgroup).
        if (visible) {
            uint key = floatBitsToUint(depth);
            [[unroll]] for (uint p = 0u; p < kRadixSortMaxPasses; ++p) {
                atomicAdd(s_depth_digits[p * kRadixSortBins + RadixSortDigit(key, p, 32u)], 1u);
            }
        }
        uint block = FlatWorkGroupIndex();
        if (block < depth_sort_params.num_blocks) {
            sort_status[block * kRadixSortBins + gl_LocalInvocationIndex] = 0u;
        }
        barrier();
        [[unroll]] for (uint p = 0u; p < kRadixSortMaxPasses; ++p) {
            uint c = s_depth_digits[p * kRadixSortBins + gl_LocalInvocationIndex];
            if (c != 0u) {
                atomicAdd(depth_sort_state.histogram[p * kRadixSortBins + gl_LocalInvocationIndex],
                          c);
            }
        }
    }
}
