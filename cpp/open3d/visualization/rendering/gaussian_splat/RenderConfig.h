// Every knob of the Gaussian splat pipeline, shared by all backends. Defaults reproduce
// the original 3DGS rasterizer (docs/DESIGN.md "Numerical rules"); other values are measured
// options.
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace open3d {
namespace visualization {
namespace rendering {

/// Side of the square screen tiles (pixels), as in the 3DGS rasterizer (BLOCK_X = BLOCK_Y).
inline constexpr int kTileSize = 16;

/// Depth order of each tile's splats (GPU backends; the CPU reference is always exact).
enum class SortMode {
    /// Exact float32 view depth, ties by splat index: the reference's order, from one stable
    /// sort of the visible splats by depth and one stable sort of the entries by tile (radix
    /// sorts over the whole frame). When the entries pass the capacity the farthest splats
    /// are dropped everywhere.
    kExact,
    /// The same order from per-tile bins: the projection counts each tile's entries, the
    /// entries go into their tile's bin and each tile is sorted by (depth, splat index) on
    /// its own (docs/sort-options.md "Per-tile bins option"): five dependent passes in place
    /// of about 25, but slower on real scenes as built today (docs/perf/h100.md). When the
    /// entries pass the capacity, whole tiles are dropped from the first that does not fit.
    kExactTileBins,
    /// The seed's single 32-bit key per entry: tile index in the top ceil(log2(tiles)) bits,
    /// the truncated bits of the normalised depth below, ties in the projection's
    /// (nondeterministic) append order. Only 7-11 mantissa bits of depth at 1080p-8K, so
    /// near splats can swap: a measured option (docs/sort-options.md, "Packed 32-bit key option").
    kPackedKey32,
};

/// The view depth that orders splats front to back (ties by splat index) and culls them at
/// the near plane, on every backend (docs/accuracy.md).
enum class DepthOrder {
    /// The original 3DGS rasterizer's float32 view z, computed in its operation order
    /// (shader::ReferenceViewDepth): splats whose depths differ by less than a float32 step
    /// blend in the original's order. Its float32 world-space arithmetic loses the order of
    /// near splats far from the origin (about 1e4 units and beyond).
    kReference,
    /// Depth from the camera-relative position (shader::SortDepth): accurate to float32
    /// rounding of the position relative to the camera wherever the scene lies.
    kCameraRelative,
};

/// How a GPU backend finds a view's level-of-detail cut (RenderConfig::lod_budget); every
/// choice gives the same cut, bit for bit (docs/lod.md "The cut on the GPU").
enum class LodCutSearch {
    /// kFromRoot where it measured faster (WalksLodCut: at least kLodWalkMinInner inner
    /// nodes and a budget of at most a quarter of them), else kEveryNode.
    kAuto,
    /// Size every inner node each frame: a fixed cost per node, few dispatches.
    kEveryNode,
    /// Walk down from the root, level by level, sizing only the nodes whose parent opens
    /// above the scene's previous threshold (less a quarter octave): a cost that follows the
    /// cut, not the hierarchy, and a few dispatches per level of the tree.
    kFromRoot,
};

/// LodCutSearch::kAuto walks from the root from this many inner nodes on.
inline constexpr uint32_t kLodWalkMinInner = 2000000;

struct RenderConfig {
    /// Splats with view-space z <= near_plane are culled (3DGS: 0.2).
    double near_plane = 0.2;
    /// Upper bound on the SH degree evaluated; the scene's own degree is used when lower.
    int sh_degree = 3;
    /// Mip-Splatting style compensation: opacity *= sqrt(max(2.5e-5, det(cov) / det(cov + 0.3 I))).
    bool antialias = false;
    /// Colour where nothing covers the pixel: out.rgb = C + T * background, alpha = 1 - T
    /// (the 3DGS rule). Black keeps the output premultiplied.
    Eigen::Vector3d background = Eigen::Vector3d::Zero();
    /// A splat touching more tiles than this emits no entries (flag kEntriesDropped).
    uint32_t max_tiles_per_splat = 1u << 16;
    /// Entries beyond this total are dropped, farthest splats first (flag kEntriesDropped).
    uint64_t max_tile_entries_total = 1ull << 26;
    /// Which depth orders the splats and culls them at the near plane; see DepthOrder.
    DepthOrder depth_order = DepthOrder::kReference;
    /// Exact depth order by two global sorts (default) or in per-tile bins, or the seed's
    /// packed 32-bit key; see SortMode.
    SortMode sort_mode = SortMode::kExact;
    /// GPU storage of the splat attributes: false = `exact` (fp32 where it matters), true =
    /// `compact` (fp16 scale, rotation, colour and SH; <= 140 B/splat at SH degree 3). GPU
    /// backends re-upload the scene when it changes; the CPU reference ignores it.
    bool compact_storage = false;
    /// A scene drawn through a level-of-detail hierarchy (GPU backends'
    /// SetSceneHierarchy): the most nodes the view's cut may keep; 0 (the default) keeps
    /// every leaf, the exact scene. Ignored for plain scenes.
    uint64_t lod_budget = 0;
    /// A hierarchy's frame time to hold, in milliseconds of GPU time (GPU backends; 0, the
    /// default, off): each frame's budget is chosen from the last frames' GPU times
    /// (LodBudgetController.h), at most lod_budget nodes where that is set. The cut, and so the
    /// image, then depends on how fast the device is. Ignored for plain scenes and by the CPU
    /// reference.
    double lod_target_ms = 0.0;
    /// How the cut is found; see LodCutSearch (the cut is the same).
    LodCutSearch lod_cut_search = LodCutSearch::kAuto;
    /// GPU backends skip the geometry stage when the scene, the camera and this config are
    /// unchanged since the last frame; benchmarks turn it off to time the whole pipeline every
    /// frame.
    bool reuse_geometry = true;

    /// Throws core::Open3DError for a near plane that is not a positive finite number (a
    /// negative one would keep splats behind the camera, mirrored, and NaN would cull
    /// every splat), or a lod_target_ms that is negative or not finite. Every backend calls it
    /// before the geometry stage.
    void Validate() const;
};

/// Whether two configs give the same geometry stage: every field but the background (a
/// composite parameter) and reuse_geometry. With lod_target_ms, backends compare the configs
/// with the budget it chose in lod_budget, and a new target runs the geometry stage once: a
/// reused stage measures no time to steer by.
bool SameGeometryConfig(const RenderConfig& a, const RenderConfig& b);

/// Bits of RenderStats::error_flags (the same bits the GPU backends read back).
inline constexpr uint32_t kEntriesDropped = 1u << 0;
inline constexpr uint32_t kCountsClamped = 1u << 1;

/// What a frame did, for logs, benchmarks and tests.
struct RenderStats {
    int64_t num_splats = 0;
    int64_t num_visible = 0;       ///< splats that survived projection (>= 1 tile)
    int64_t num_tile_entries = 0;  ///< (tile, splat) pairs composited
    int64_t lod_cut_nodes = 0;     ///< nodes of the level-of-detail cut (0: no hierarchy)
    /// The walk from the root (LodCutSearch::kFromRoot): inner nodes it sized and walks it
    /// took (2 when the view's previous threshold was too coarse); 0 and 0 without a walk.
    int64_t lod_walk_visited = 0;
    int lod_walks = 0;
    uint32_t error_flags = 0;  ///< kEntriesDropped | kCountsClamped
    double geometry_ms = 0.0;  ///< project + tile entries + sort
    double composite_ms = 0.0;
    /// GPU time per pass from timestamp queries (GPU backends only; 0 where not measured).
    double gpu_project_ms = 0.0;    ///< projection (+ dispatch arguments)
    double gpu_sort_ms = 0.0;       ///< depth sort, scan, emission and tile sort
    double gpu_composite_ms = 0.0;  ///< composite stage composite
    double gpu_merge_ms = 0.0;      ///< depth merge (offscreen depth readback only)
    /// Parts of gpu_sort_ms: depth sort, scan + entry emission, tile sort.
    double gpu_depth_sort_ms = 0.0, gpu_scan_emit_ms = 0.0, gpu_tile_sort_ms = 0.0;
    /// Part of gpu_project_ms: the level-of-detail cut chosen on the GPU (0 without a
    /// hierarchy).
    double gpu_lod_cut_ms = 0.0;
    /// Part of gpu_lod_cut_ms: the cut's bits made the projection's list.
    double gpu_lod_list_ms = 0.0;
    /// Host time of the frame in the Vulkan backend: recording commands (0 when a recording
    /// was submitted again), submitting, waiting for the GPU's fence, copying the images out.
    /// A batch reports its totals divided by its views. docs/perf/ has the breakdown.
    double host_record_ms = 0.0, host_submit_ms = 0.0, host_wait_ms = 0.0;
    double host_readback_ms = 0.0;
    /// Compute dispatches one view's recording holds, and how many of them wait for the one
    /// before through a barrier (the frame's chain of dependent steps). The Vulkan backend's
    /// submission path (Render, batches: the recording's counts divided by its views); 0
    /// elsewhere.
    int dispatches = 0, dependent_dispatches = 0;
    /// Bytes the backend keeps on the GPU for the scene between frames (0 for the CPU).
    int64_t gpu_scene_bytes = 0;
    /// True when geometry stage was reused because neither the scene nor the view changed.
    bool geometry_reused = false;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
