#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "GaussianSplatLodContract.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"

namespace open3d {
namespace visualization {
namespace rendering {

static_assert(shader::kGaussianTileSize == static_cast<uint32_t>(kTileSize));
static_assert(shader::kErrorEntriesDropped == kEntriesDropped);
static_assert(shader::kErrorCountsClamped == kCountsClamped);

uint16_t FloatToHalf(float value) {
    const uint32_t bits = std::bit_cast<uint32_t>(value);
    const uint32_t sign = (bits >> 16) & 0x8000u;
    const uint32_t exponent = (bits >> 23) & 0xFFu;
    uint32_t mantissa = bits & 0x7FFFFFu;
    if (exponent == 0xFFu) {  // inf, NaN (keep a quiet NaN payload bit)
        return static_cast<uint16_t>(sign | 0x7C00u | (mantissa ? 0x200u : 0u));
    }
    const int half_exponent = static_cast<int>(exponent) - 127 + 15;
    if (half_exponent >= 0x1F) return static_cast<uint16_t>(sign | 0x7C00u);  // overflow
    if (half_exponent <= 0) {
        // Subnormal half (or zero): shift the implicit-one mantissa into place.
        if (half_exponent < -10) return static_cast<uint16_t>(sign);
        mantissa |= 0x800000u;
        const uint32_t shift = static_cast<uint32_t>(14 - half_exponent);
        uint32_t half_mantissa = mantissa >> shift;
        const uint32_t remainder = mantissa & ((1u << shift) - 1u);
        const uint32_t halfway = 1u << (shift - 1u);
        if (remainder > halfway || (remainder == halfway && (half_mantissa & 1u))) {
            ++half_mantissa;  // may carry into the exponent: still the right encoding
        }
        return static_cast<uint16_t>(sign | half_mantissa);
    }
    uint32_t half = sign | (static_cast<uint32_t>(half_exponent) << 10) | (mantissa >> 13);
    const uint32_t remainder = mantissa & 0x1FFFu;
    if (remainder > 0x1000u || (remainder == 0x1000u && (half & 1u))) ++half;  // carry ok
    return static_cast<uint16_t>(half);
}

float HalfToFloat(uint16_t half) {
    const uint32_t sign = static_cast<uint32_t>(half & 0x8000u) << 16;
    const uint32_t exponent = (half >> 10) & 0x1Fu;
    const uint32_t mantissa = half & 0x3FFu;
    if (exponent == 0) {  // zero or subnormal: mantissa * 2^-24
        const float magnitude = std::ldexp(static_cast<float>(mantissa), -24);
        return sign ? -magnitude : magnitude;
    }
    if (exponent == 0x1F) return std::bit_cast<float>(sign | 0x7F800000u | (mantissa << 13));
    return std::bit_cast<float>(sign | ((exponent - 15 + 127) << 23) | (mantissa << 13));
}

uint64_t PackedGaussianSplats::BytesPerSplat() const {
    return 4 * sizeof(float) + sizeof(uint32_t) * (shape_words_per_splat + sh_words_per_splat);
}

namespace {

// Writes `values` as fp32 bits (exact) or fp16 pairs (compact, zero-padded to a word) at
// `out`; returns the word after them.
uint32_t* WriteWords(const double* values, int count, SplatPrecision precision, uint32_t* out) {
    if (precision == SplatPrecision::kExact) {
        for (int k = 0; k < count; ++k) {
            *out++ = std::bit_cast<uint32_t>(static_cast<float>(values[k]));
        }
        return out;
    }
    for (int k = 0; k < count; k += 2) {
        const uint32_t lo = FloatToHalf(static_cast<float>(values[k]));
        const uint32_t hi = k + 1 < count ? FloatToHalf(static_cast<float>(values[k + 1])) : 0u;
        *out++ = lo | (hi << 16);
    }
    return out;
}

uint32_t WordsFor(int values, SplatPrecision precision) {
    return precision == SplatPrecision::kExact ? static_cast<uint32_t>(values)
                                               : static_cast<uint32_t>((values + 1) / 2);
}

}  // namespace

PackedGaussianSplats PackedSplatLayout(int sh_degree, SplatPrecision precision) {
    if (sh_degree < 0 || sh_degree > 3) core::ThrowError("a packing of SH degree {}", sh_degree);
    PackedGaussianSplats packed;
    packed.precision = precision;
    packed.sh_degree = sh_degree;
    packed.shape_words_per_splat = WordsFor(10, precision);
    packed.sh_words_per_splat = WordsFor(3 * t::geometry::NumSHRestCoeffs(sh_degree), precision);
    static_assert(shader::kShapeWordsExact == 10 && shader::kShapeWordsCompact == 5);
    return packed;
}

PackedGaussianSplats PackGaussianSplatAttrs(const t::geometry::PointCloud& cloud,
                                            SplatPrecision precision, int max_sh_degree) {
    const t::geometry::GaussianSplatArrays a = cloud.GetGaussianSplatArrays();  // validates
    const int64_t n = a.num_points;
    if (n > static_cast<int64_t>(std::numeric_limits<uint32_t>::max())) {
        core::ThrowError("PackGaussianSplatAttrs: {} splats, at most 2^32 - 1 fit a splat index",
                         n);
    }
    PackedGaussianSplats packed =
        PackedSplatLayout(std::clamp(max_sh_degree, 0, a.sh_degree), precision);
    packed.num_splats = n;
    packed.positions.resize(4 * n);
    packed.shape.resize(packed.shape_words_per_splat * n);
    packed.sh.resize(packed.sh_words_per_splat * n);
    PackGaussianSplatAttrsInto(cloud, packed,
                               {packed.positions.data(), packed.shape.data(), packed.sh.data()},
                               packed.center_min, packed.center_max);
    packed.visibility.assign((n + 31) / 32, 0u);
    SetSplatVisibility(packed.visibility, 0, n, true);
    return packed;
}

void PackGaussianSplatAttrsInto(const t::geometry::PointCloud& cloud,
                                const PackedGaussianSplats& layout, PackedSplatSpans out,
                                Eigen::Vector3d& center_min, Eigen::Vector3d& center_max) {
    PackGaussianSplatRangeInto(cloud, 0, cloud.NumPoints(), layout, out, center_min, center_max);
}

void PackGaussianSplatRangeInto(const t::geometry::PointCloud& cloud, int64_t begin, int64_t end,
                                const PackedGaussianSplats& layout, PackedSplatSpans out,
                                Eigen::Vector3d& center_min, Eigen::Vector3d& center_max) {
    const t::geometry::GaussianSplatArrays a = cloud.GetGaussianSplatArrays();  // validates
    if (begin < 0 || begin > end || end > a.num_points) {
        core::ThrowError("packing splats [{}, {}) of a cloud of {}", begin, end, a.num_points);
    }
    if (a.sh_degree < layout.sh_degree) {
        core::ThrowError("packing splats of SH degree {} at degree {}", a.sh_degree,
                         layout.sh_degree);
    }
    const int rest_values = 3 * t::geometry::NumSHRestCoeffs(layout.sh_degree);
    std::vector<double> values(std::max(10, rest_values));
    for (int64_t i = begin; i < end; ++i) {
        for (int c = 0; c < 3; ++c) *out.positions++ = a.positions[3 * i + c];
        const Eigen::Vector3d center(a.positions[3 * i], a.positions[3 * i + 1],
                                     a.positions[3 * i + 2]);
        center_min = center_min.cwiseMin(center);
        center_max = center_max.cwiseMax(center);
        // The sigmoid in double, rounded once: within half an ulp of the reference's value.
        const double logit = a.opacity[i];
        *out.positions++ = static_cast<float>(1.0 / (1.0 + std::exp(-logit)));

        for (int c = 0; c < 3; ++c) values[c] = a.scale[3 * i + c];
        const float* q = a.rot + 4 * i;
        const double norm = std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] +
                                      double(q[2]) * q[2] + double(q[3]) * q[3]);
        // A zero quaternion stays zero: the shader's rotation formula then gives the
        // identity, as Eigen's does for the CPU reference.
        for (int c = 0; c < 4; ++c) values[3 + c] = norm > 0.0 ? q[c] / norm : 0.0;
        for (int c = 0; c < 3; ++c) values[7 + c] = a.f_dc[3 * i + c];
        out.shape = WriteWords(values.data(), 10, layout.precision, out.shape);

        if (rest_values > 0) {
            // The scene's [Nc, 3] block starts with the packed degree's coefficients.
            const float* rest = a.f_rest + i * a.num_rest * 3;
            for (int k = 0; k < rest_values; ++k) values[k] = rest[k];
            out.sh = WriteWords(values.data(), rest_values, layout.precision, out.sh);
        }
    }
}

void SetSplatVisibility(std::vector<uint32_t>& mask, int64_t begin, int64_t end, bool visible) {
    for (int64_t i = begin; i < end; ++i) {
        const uint32_t bit = 1u << (i & 31);
        if (visible) {
            mask[i >> 5] |= bit;
        } else {
            mask[i >> 5] &= ~bit;
        }
    }
}

int EvaluatedShDegree(const RenderConfig& config, int packed_sh_degree) {
    return std::clamp(config.sh_degree, 0, packed_sh_degree);
}

uint32_t SortKeyTileBits(uint64_t num_tiles) {
    // Tile indices 0..n - 1 plus one key past them (gaussian_emit.comp's filler for a
    // span it could not reproduce): the bit width of n, 13 bits for 4096 tiles.
    const uint32_t bits = static_cast<uint32_t>(std::bit_width(num_tiles));
    return std::clamp(bits, shader::kSortKeyMinTileBits, shader::kSortKeyMaxTileBits);
}

double PackedSortKeyFar(const camera::PinholeCamera& camera, double near_plane,
                        const Eigen::Vector3d& center_min, const Eigen::Vector3d& center_max) {
    const Eigen::Matrix3d r = camera.GetRotation();
    const double t_z = camera.GetTranslation().z();
    double far = -std::numeric_limits<double>::infinity();
    if ((center_min.array() <= center_max.array()).all()) {
        for (int corner = 0; corner < 8; ++corner) {
            const Eigen::Vector3d p((corner & 1) ? center_max.x() : center_min.x(),
                                    (corner & 2) ? center_max.y() : center_min.y(),
                                    (corner & 4) ? center_max.z() : center_min.z());
            far = std::max(far, r.row(2).dot(p) + t_z);
        }
    }
    // Nothing can be visible then; any far > near keeps the scale finite and positive.
    return std::isfinite(far) && far > near_plane ? far : near_plane + 1.0;
}

CameraCenterSplit SplitCameraCenter(const camera::PinholeCamera& camera) {
    const Eigen::Vector3d c = camera.GetCenter();
    const double center[3] = {c.x(), c.y(), c.z()};
    return shader::SplitCameraCenter(center);
}

ReferenceDepthRow GetReferenceDepthRow(const camera::PinholeCamera& camera) {
    // The float32 matrix the original is given: R and t = -R c, each rounded from double.
    const Eigen::Matrix3d r = camera.GetRotation();
    const Eigen::Vector3d t = camera.GetTranslation();
    return {float(r(2, 0)), float(r(2, 1)), float(r(2, 2)), float(t.z())};
}

bool UsesPackedSortKey(const RenderConfig& config) {
    return config.sort_mode == SortMode::kPackedKey32;
}

GeometryStageChoices ChooseGeometryStage(const camera::PinholeCamera& camera,
                                         const RenderConfig& config,
                                         const ViewPackingInputs& inputs) {
    const cpu::TileGrid grid = cpu::TileGrid::ForImage(camera.width, camera.height);
    if (grid.tiles_x > 0xFFFF || grid.tiles_y > 0xFFFF) {
        core::ThrowError("PackGaussianViewParams: {}x{} tiles, at most 65535 per axis",
                         grid.tiles_x, grid.tiles_y);
    }
    // Capacities stay below the scan's saturation value so "saturated" means "over".
    const uint64_t saturation = shader::kScanSaturation;
    const uint32_t config_limit =
        static_cast<uint32_t>(std::min<uint64_t>(config.max_tile_entries_total, saturation - 1));
    GeometryStageChoices choices;
    choices.num_splats = uint32_t(inputs.num_splats);
    choices.sh_degree = uint32_t(EvaluatedShDegree(config, inputs.packed_sh_degree));
    choices.antialias = config.antialias;
    choices.packed_key = UsesPackedSortKey(config);
    choices.binned = config.sort_mode == SortMode::kExactTileBins;
    choices.num_tiles = static_cast<uint32_t>(grid.NumTiles());
    choices.tile_bits = SortKeyTileBits(static_cast<uint64_t>(grid.NumTiles()));
    choices.entry_capacity = std::min(config_limit, inputs.entry_capacity);
    choices.entry_capacity_allocated = inputs.entry_capacity;
    choices.lod_cut_search = config.lod_cut_search;
    return choices;
}

uint32_t PackedLodBudget(const RenderConfig& config) {
    return config.lod_budget == 0
               ? shader::kLodOpenAll
               : static_cast<uint32_t>(std::min<uint64_t>(config.lod_budget, shader::kLodOpenAll));
}

PackedView PackGaussianView(const camera::PinholeCamera& camera, const RenderConfig& config,
                            const ViewPackingInputs& inputs) {
    camera.Validate();
    const GeometryStageChoices choices = ChooseGeometryStage(camera, config, inputs);
    const Eigen::Matrix3d r = camera.GetRotation();
    // The camera centre as float32 c_hi plus its rounding error c_lo (shader::CameraRelative).
    const CameraCenterSplit center = SplitCameraCenter(camera);
    auto row = [&](int i) { return shader::vec3{float(r(i, 0)), float(r(i, 1)), float(r(i, 2))}; };
    const uint64_t saturation = shader::kScanSaturation;

    shader::GaussianViewParams p{};
    p.rotation_row0 = row(0);
    p.rotation_row1 = row(1);
    p.rotation_row2 = row(2);
    p.center_low_x = center.low[0];
    p.center_low_y = center.low[1];
    p.center_low_z = center.low[2];
    p.center_high = {center.high[0], center.high[1], center.high[2]};
    p.fx = float(camera.fx);
    p.fy = float(camera.fy);
    p.cx = float(camera.cx);
    p.cy = float(camera.cy);
    p.guard_x = float(1.3 * camera.GetTanHalfFovX());
    p.guard_y = float(1.3 * camera.GetTanHalfFovY());
    p.guard_center_x = float(camera.GetImageCenterTanX());
    p.guard_center_y = float(camera.GetImageCenterTanY());
    p.near_plane = float(config.near_plane);
    // A positive scale is the packed key's, kept finite for a tiny depth range.
    if (choices.packed_key) {
        const double far =
            PackedSortKeyFar(camera, config.near_plane, inputs.center_min, inputs.center_max);
        p.packed_depth_scale = static_cast<float>(
            std::min<double>(1.0 / (far - config.near_plane), std::numeric_limits<float>::max()));
    }
    const cpu::TileGrid grid = cpu::TileGrid::ForImage(camera.width, camera.height);
    p.width = uint32_t(camera.width);
    p.height = uint32_t(camera.height);
    p.tiles_x = uint32_t(grid.tiles_x);
    p.tiles_y = uint32_t(grid.tiles_y);
    p.entry_capacity = choices.entry_capacity;
    p.max_tiles_per_splat = config.max_tiles_per_splat;
    p.max_tile_entries_total =
        static_cast<uint32_t>(std::min<uint64_t>(config.max_tile_entries_total, saturation - 1));
    p.tile_bits = choices.tile_bits;
    p.num_splats = choices.num_splats;
    p.sh_degree = choices.sh_degree;
    p.antialias = choices.antialias ? 1u : 0u;
    p.sh_words_per_splat = inputs.sh_words_per_splat;
    p.scene_depth_present = inputs.scene_depth_present ? 1u : 0u;
    const bool exact = inputs.precision == SplatPrecision::kExact;
    p.splat_precision = exact ? shader::kPrecisionExact : shader::kPrecisionCompact;
    p.shape_words_per_splat = exact ? shader::kShapeWordsExact : shader::kShapeWordsCompact;
    p.entry_capacity_allocated = choices.entry_capacity_allocated;
    const ReferenceDepthRow m = GetReferenceDepthRow(camera);
    p.reference_m2 = m.m2;
    p.reference_m6 = m.m6;
    p.reference_m10 = m.m10;
    p.reference_m14 = m.m14;
    p.depth_order = config.depth_order == DepthOrder::kReference
                        ? shader::kDepthOrderReference
                        : shader::kDepthOrderCameraRelative;
    p.lod_budget = PackedLodBudget(config);
    return {p, choices};
}

shader::GaussianViewParams PackGaussianViewParams(const camera::PinholeCamera& camera,
                                                  const RenderConfig& config,
                                                  const ViewPackingInputs& inputs) {
    return PackGaussianView(camera, config, inputs).params;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
