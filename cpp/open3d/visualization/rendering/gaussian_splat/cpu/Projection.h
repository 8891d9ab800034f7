// Geometry stage, step 1 of the CPU reference: per-splat projection, exactly the 3DGS
// rasterizer's preprocess (docs/DESIGN.md "Numerical rules"), computed in double precision.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

/// Why a splat produced no tile entries.
enum class CullReason : uint8_t {
    kVisible = 0,
    kNearPlane,   ///< view-space z <= RenderConfig::near_plane
    kDegenerate,  ///< det(cov2D + 0.3 I) <= 0 or not finite (never for finite inputs)
    kNoTiles,     ///< the tile rectangle of the 3-sigma square is empty
};

/// One splat after projection. Index i of ProjectSplats' result is splat i of the cloud.
/// Fields past `cull` are meaningful only as far as the splat got (all when visible).
struct ProjectedSplat {
    CullReason cull = CullReason::kNearPlane;
    double x = 0.0, y = 0.0;  ///< centre in pixels: fx * X / Z + cx, fy * Y / Z + cy
    double depth = 0.0;       ///< view-space Z
    /// The depth that orders splats and culls them at the near plane, float32, exactly as the
    /// GPU computes it (ties broken by splat index): shader::ReferenceViewDepth or
    /// shader::SortDepth, as RenderConfig::depth_order says.
    float sort_depth = 0.0f;
    /// The centre the composite's float32 threshold decisions read, as the original takes
    /// them: its own float32 pixel centre (OriginalPixelCenter) with DepthOrder::kReference,
    /// (x, y) rounded to float32 with kCameraRelative. The blended values use x, y.
    float original_x = 0.0f, original_y = 0.0f;
    /// 2D covariance after the +0.3 dilation: [[cov_a, cov_b], [cov_b, cov_c]] (pixels^2).
    double cov_a = 0.0, cov_b = 0.0, cov_c = 0.0;
    /// Inverse of the dilated covariance: [[conic_a, conic_b], [conic_b, conic_c]].
    double conic_a = 0.0, conic_b = 0.0, conic_c = 0.0;
    /// conic_a conic_c - conic_b^2 = 1 / det(dilated cov); 0 (unknown) keeps whole rows.
    double det_q = 0.0;
    int radius = 0;                 ///< ceil(3 sqrt(lambda_max)) in pixels
    double opacity = 0.0;           ///< sigmoid(logit), times the antialias factor when enabled
    std::array<double, 3> color{};  ///< max(0, 0.5 + SH(direction))
    /// Tile rectangle [rect_min, rect_max) in tile units (16 px), clamped to the grid.
    int rect_min_x = 0, rect_min_y = 0, rect_max_x = 0, rect_max_y = 0;

    bool IsVisible() const { return cull == CullReason::kVisible; }
    /// Tiles of the 3DGS rectangle.
    int64_t NumTiles() const {
        return static_cast<int64_t>(rect_max_x - rect_min_x) * (rect_max_y - rect_min_y);
    }
    /// Columns [first, last) of tile row ty (in the rectangle) that get an entry:
    /// shader::TileRowSpan on this splat's values rounded to float32, as the GPU stores them.
    std::pair<int, int> RowSpan(int ty) const;
    /// Entries the splat emits: the rectangle's tiles that RowSpan keeps.
    int64_t NumEntries() const;
};

/// Tiles covering the image: ceil(W / 16) x ceil(H / 16).
struct TileGrid {
    int tiles_x = 0;
    int tiles_y = 0;
    static TileGrid ForImage(int width, int height) {
        return {(width + kTileSize - 1) / kTileSize, (height + kTileSize - 1) / kTileSize};
    }
    int64_t NumTiles() const { return static_cast<int64_t>(tiles_x) * tiles_y; }
};

/// Screen-space parameters derived from a 2D covariance (before dilation).
struct ScreenEllipse {
    bool degenerate = false;  ///< det of the dilated covariance == 0
    double cov_a = 0.0, cov_b = 0.0, cov_c = 0.0;
    double conic_a = 0.0, conic_b = 0.0, conic_c = 0.0;
    double det_q = 0.0;  ///< 1 / det of the dilated covariance
    int radius = 0;
    double opacity_scale = 1.0;  ///< antialias factor (1 when antialias is off)
};

/// Adds 0.3 to the diagonal, inverts, and takes the 3-sigma radius from the larger
/// eigenvalue mid + sqrt(max(0.1, mid^2 - det)) (clamped to shader::kMaxSplatRadius);
/// antialias gives the opacity factor. `det_raw` is det of the undilated covariance, given
/// by a caller that can compute it without cancellation; the dilated det is
/// det_raw + 0.3 (a + c) + 0.09, and a non-positive or non-finite one culls.
ScreenEllipse ComputeScreenEllipse(double cov_a, double cov_b, double cov_c, double det_raw,
                                   bool antialias);
/// The 3DGS form for callers that only have the covariance (tests): the dilated det is
/// (a + 0.3)(c + 0.3) - b^2, and 0 (or a non-finite value) culls.
ScreenEllipse ComputeScreenEllipse(double cov_a, double cov_b, double cov_c, bool antialias);

/// 3DGS getRect: rect_min = clamp((int)((p - r) / 16)), rect_max = clamp((int)((p + r + 15) / 16))
/// per axis, clamped to [0, tiles]. Writes [min, max) into the splat.
void ComputeTileRect(double x, double y, int radius, const TileGrid& grid, ProjectedSplat& splat);

/// Rows x, y and w of the original rasterizer's float32 full projection matrix P [R | t]
/// (column-major m[0..15] in its code): P scales view x and y by 2 fx / W and 2 fy / H
/// (1 / tan(fov / 2)) and copies view z into w, so each entry is one float32 product of two
/// float32 values, whichever way the matrix product was evaluated. Valid for a principal
/// point at the image centre, the only camera the original supports.
struct OriginalProjection {
    float row_x[4], row_y[4], row_w[4];
    int width = 0, height = 0;
    bool centered = false;  ///< principal point at ((W - 1) / 2, (H - 1) / 2)
};
OriginalProjection GetOriginalProjection(const camera::PinholeCamera& camera);

/// The original's pixel centre of world position p, bit for bit as its preprocess computes
/// it: p_hom = m p with its fused multiply-adds (as shader::ReferenceViewDepth), p_proj =
/// p_hom * (1 / (p_hom.w + 1e-7)), then ndc2Pix ((v + 1) S - 1) / 2 in double (its literals
/// are doubles) rounded to float32. Without a centred principal point: (x, y) rounded.
std::array<float, 2> OriginalPixelCenter(const OriginalProjection& m, const float* position,
                                         double x, double y);

/// Projects every splat of a valid Gaussian splat cloud for one camera, multi-threaded.
/// Throws core::Open3DError for an invalid cloud or camera.
std::vector<ProjectedSplat> ProjectSplats(const t::geometry::PointCloud& cloud,
                                          const camera::PinholeCamera& camera,
                                          const RenderConfig& config);

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
