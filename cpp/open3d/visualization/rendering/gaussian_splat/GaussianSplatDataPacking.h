// CPU-side packing of what the GPU projection reads (docs/vulkan.md "Geometry stage"): per-splat
// attribute buffers from a Gaussian splat cloud (once per scene change) and the per-frame
// GaussianViewParams. No Vulkan here: the layouts are GaussianSplatProjectionContract.h's, so the
// CPU, Vulkan and Metal layers all pack the same bytes.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

#include "GaussianSplatTileListContract.h"
#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

namespace open3d {
namespace visualization {
namespace rendering {

/// How the per-splat attributes are stored on the GPU.
enum class SplatPrecision {
    /// fp32 everything (the default; the accuracy target against the CPU reference).
    kExact,
    /// fp16 scale, rotation, f_dc and SH; centre and opacity stay fp32 (<= 140 B/splat).
    kCompact,
};

/// The precision RenderConfig::compact_storage (or a pool's compact_storage) asks for.
inline SplatPrecision SplatPrecisionFor(bool compact_storage) {
    return compact_storage ? SplatPrecision::kCompact : SplatPrecision::kExact;
}

/// Per-splat GPU attributes of one cloud, ready to upload. Shapes use splats as rows.
struct PackedGaussianSplats {
    SplatPrecision precision = SplatPrecision::kExact;
    int64_t num_splats = 0;
    int sh_degree = 0;                   ///< degree packed: min(scene degree, max asked)
    uint32_t shape_words_per_splat = 0;  ///< kShapeWordsExact / kShapeWordsCompact
    uint32_t sh_words_per_splat = 0;     ///< 0 at degree 0
    std::vector<float> positions;        ///< [N, 4]: x, y, z, sigmoid(opacity logit)
    /// [N, shape words]: scale xyz (linear), unit quaternion wxyz, f_dc rgb; fp32 bits
    /// (exact) or fp16 pairs, low half first (compact).
    std::vector<uint32_t> shape;
    /// [N, sh words]: f_rest as [Nc, 3] (coefficient-major, channel last) for the packed
    /// degree; fp32 bits or fp16 pairs. Empty at degree 0: nothing to upload or bind.
    std::vector<uint32_t> sh;
    std::vector<uint32_t> visibility;  ///< [ceil(N / 32)]: bit i of word i / 32 = splat i shown
    /// Axis-aligned box of the splat centres (min > max when there are none): bounds the
    /// view depth of every splat for the packed sort key's far plane.
    Eigen::Vector3d center_min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d center_max = -center_min;

    /// Bytes per splat of positions + shape + sh (the visibility mask adds 1/8).
    uint64_t BytesPerSplat() const;
};

/// The sizes a packing of splats of SH degree `sh_degree` (0..3) gets: precision, degree and
/// words per splat, no splats and empty attribute vectors (what a scene whose splats arrive
/// later is allocated from).
PackedGaussianSplats PackedSplatLayout(int sh_degree, SplatPrecision precision);

/// Packs a valid Gaussian splat cloud: the sigmoid is applied to the opacity logits and
/// quaternions are normalised here (in double, then rounded), SH is cut to
/// min(scene degree, max_sh_degree). Every splat starts visible. Throws core::Open3DError
/// for an invalid cloud or more than 2^32 - 1 splats.
PackedGaussianSplats PackGaussianSplatAttrs(const t::geometry::PointCloud& cloud,
                                            SplatPrecision precision = SplatPrecision::kExact,
                                            int max_sh_degree = 3);

/// Where PackGaussianSplatAttrsInto writes a cloud's n splats: [n, 4] floats, [n, shape
/// words] and [n, sh words] of the layout (a mapped staging buffer, say).
struct PackedSplatSpans {
    float* positions = nullptr;
    uint32_t* shape = nullptr;
    uint32_t* sh = nullptr;  ///< unused at SH degree 0
};

/// Packs a valid cloud's splats as PackGaussianSplatAttrs does, at `layout`'s precision and
/// SH degree (at most the cloud's), into `out`, and widens center_min / center_max to hold
/// their centres. Throws core::Open3DError for an invalid cloud or one of a lower degree.
void PackGaussianSplatAttrsInto(const t::geometry::PointCloud& cloud,
                                const PackedGaussianSplats& layout, PackedSplatSpans out,
                                Eigen::Vector3d& center_min, Eigen::Vector3d& center_max);
/// PackGaussianSplatAttrsInto for the cloud's splats [begin, end) alone, written from the
/// start of `out` (a large scene packed a part per thread).
void PackGaussianSplatRangeInto(const t::geometry::PointCloud& cloud, int64_t begin, int64_t end,
                                const PackedGaussianSplats& layout, PackedSplatSpans out,
                                Eigen::Vector3d& center_min, Eigen::Vector3d& center_max);

/// Sets (visible = true) or clears the bits of splats [begin, end) in a visibility mask.
void SetSplatVisibility(std::vector<uint32_t>& mask, int64_t begin, int64_t end, bool visible);

/// What the frame's view parameters depend on besides camera and config.
struct ViewPackingInputs {
    int64_t num_splats = 0;
    int packed_sh_degree = 0;  ///< PackedGaussianSplats::sh_degree
    SplatPrecision precision = SplatPrecision::kExact;
    uint32_t sh_words_per_splat = 0;
    uint32_t entry_capacity = 0;       ///< tile entries the caller allocated
    bool scene_depth_present = false;  ///< a mesh is visible in this view (composite stage)
    /// PackedGaussianSplats::center_min / center_max; only RenderConfig::sort_mode ==
    /// kPackedKey32 reads them (PackedSortKeyFar).
    Eigen::Vector3d center_min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d center_max = -center_min;
};

/// What the host decides for one frame's geometry stage, from its own camera, config and
/// scene: the pipelines and passes are picked from these values, never read back out of the
/// packed GaussianViewParams (which PackGaussianView fills from the same values).
struct GeometryStageChoices {
    uint32_t num_splats = 0;
    uint32_t sh_degree = 0;  ///< evaluated: EvaluatedShDegree
    bool antialias = false;
    bool packed_key = false;  ///< config.sort_mode == kPackedKey32
    bool binned = false;      ///< config.sort_mode == kExactTileBins
    uint32_t tile_bits = 0;   ///< SortKeyTileBits of the frame's tile count
    uint32_t num_tiles = 0;   ///< the frame's tiles (tiles_x * tiles_y)
    /// Tile entries used: min(allocated, max_tile_entries_total), below shader::kScanSaturation.
    uint32_t entry_capacity = 0;
    uint32_t entry_capacity_allocated = 0;              ///< ViewPackingInputs::entry_capacity
    LodCutSearch lod_cut_search = LodCutSearch::kAuto;  ///< RenderConfig::lod_cut_search
};
GeometryStageChoices ChooseGeometryStage(const camera::PinholeCamera& camera,
                                         const RenderConfig& config,
                                         const ViewPackingInputs& inputs);

/// One frame's view parameters for the GPU and the host choices they were packed from.
struct PackedView {
    shader::GaussianViewParams params;
    GeometryStageChoices choices;
};

/// The per-frame view parameters: world-to-camera rows, intrinsics, guard band
/// 1.3 tan(fov / 2) with tan(fov_x / 2) = W / (2 fx), near plane, image and tile grid,
/// the choices of ChooseGeometryStage. config.sort_mode == kPackedKey32 sets
/// packed_depth_scale = 1 / (far - near) with far from PackedSortKeyFar; kExact leaves 0.
PackedView PackGaussianView(const camera::PinholeCamera& camera, const RenderConfig& config,
                            const ViewPackingInputs& inputs);
/// PackGaussianView(...).params.
shader::GaussianViewParams PackGaussianViewParams(const camera::PinholeCamera& camera,
                                                  const RenderConfig& config,
                                                  const ViewPackingInputs& inputs);

/// SH degree the shader evaluates: config.sh_degree clamped to [0, packed degree].
int EvaluatedShDegree(const RenderConfig& config, int packed_sh_degree);

/// Key bits that hold a tile index or the one key past them (gaussian_emit.comp's filler):
/// bit width of num_tiles, clamped to [shader::kSortKeyMinTileBits, kSortKeyMaxTileBits].
uint32_t SortKeyTileBits(uint64_t num_tiles);

/// Far plane of the packed key's depth normalisation: the largest view depth of the eight
/// corners of the centre box [center_min, center_max], so no splat centre lies beyond it
/// (the exact largest visible depth would need a GPU readback or a pass over all splats
/// per frame). near_plane + 1 when the box is empty or wholly behind the near plane.
double PackedSortKeyFar(const camera::PinholeCamera& camera, double near_plane,
                        const Eigen::Vector3d& center_min, const Eigen::Vector3d& center_max);

/// The camera centre as float32 high + low (shader::SplitCameraCenter, GaussianSplatShared.h):
/// the projection works on (p - high) - low (shader::CameraRelative).
using CameraCenterSplit = shader::CameraCenterSplit;
CameraCenterSplit SplitCameraCenter(const camera::PinholeCamera& camera);

/// Row 2 of the world-to-view matrix [R | t] as the original rasterizer receives it
/// (shader::ReferenceDepthRow): GaussianViewParams::reference_m2 .. reference_m14.
using ReferenceDepthRow = shader::ReferenceDepthRow;
ReferenceDepthRow GetReferenceDepthRow(const camera::PinholeCamera& camera);

/// True when `config` selects the packed 32-bit key, false for exact order.
bool UsesPackedSortKey(const RenderConfig& config);

/// RenderConfig::lod_budget as GaussianViewParams::lod_budget holds it: 0 (no cap) becomes
/// shader::kLodOpenAll, larger counts saturate there.
uint32_t PackedLodBudget(const RenderConfig& config);

/// IEEE half from float, round to nearest even (overflow to inf, NaN kept).
uint16_t FloatToHalf(float value);
/// Float from IEEE half (exact).
float HalfToFloat(uint16_t half);

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
