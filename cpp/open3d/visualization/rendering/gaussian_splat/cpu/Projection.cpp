#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
// The float-exact arithmetic shared with the shaders, and nothing of the GPU packing.
#include "GaussianSplatShared.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

static_assert(shader::kGaussianTileSize == static_cast<uint32_t>(kTileSize));

namespace {

// The low-pass filter: every splat covers at least about one pixel.
constexpr double kDilation = 0.3;

// Conic, antialias factor and radius of e (dilated covariance set) from the undilated
// det_raw and the dilated det (> 0).
void FinishEllipse(double det_raw, double det, bool antialias, ScreenEllipse& e) {
    if (antialias) e.opacity_scale = std::sqrt(std::max(0.000025, det_raw / det));
    e.conic_a = e.cov_c / det;
    e.conic_b = -e.cov_b / det;
    e.conic_c = e.cov_a / det;
    e.det_q = 1.0 / det;
    // lambda_max = mid + sqrt(max(0.1, mid^2 - det)), with mid^2 - det written as
    // ((a - c) / 2)^2 + b^2 (the same value, without the cancellation).
    const double mid = 0.5 * (e.cov_a + e.cov_c);
    const double half_diff = 0.5 * (e.cov_a - e.cov_c);
    const double lambda1 =
        mid + std::sqrt(std::max(0.1, half_diff * half_diff + e.cov_b * e.cov_b));
    // Clamped before the conversion (shader::kMaxSplatRadius): a radius this large covers the
    // whole grid anyway.
    e.radius = static_cast<int>(
        std::min(std::ceil(3.0 * std::sqrt(lambda1)), double(shader::kMaxSplatRadius)));
}

}  // namespace

ScreenEllipse ComputeScreenEllipse(double cov_a, double cov_b, double cov_c, bool antialias) {
    ScreenEllipse e;
    e.cov_a = cov_a + kDilation;
    e.cov_b = cov_b;
    e.cov_c = cov_c + kDilation;
    const double det = e.cov_a * e.cov_c - e.cov_b * e.cov_b;
    if (det == 0.0 || !std::isfinite(det)) {
        e.degenerate = true;
        return e;
    }
    FinishEllipse(cov_a * cov_c - cov_b * cov_b, det, antialias, e);
    return e;
}

ScreenEllipse ComputeScreenEllipse(double cov_a, double cov_b, double cov_c, double det_raw,
                                   bool antialias) {
    ScreenEllipse e;
    e.cov_a = cov_a + kDilation;
    e.cov_b = cov_b;
    e.cov_c = cov_c + kDilation;
    // det(cov + 0.3 I) expanded: no cancellation between a c and b^2 (a rank-one footprint,
    // e.g. a flat splat seen edge-on, made them cancel to noise in float32); >= 0.09 for any
    // positive semi-definite covariance, so only a non-finite one is culled here (3DGS culls
    // det == 0, which exact arithmetic never reaches).
    const double det = det_raw + kDilation * (cov_a + cov_c) + kDilation * kDilation;
    // Past the float32 range the GPU's determinant is infinite: such a splat (its screen
    // extent beyond ~1e9 px) is culled by both renderers instead of each doing what its own
    // arithmetic gives (docs/accuracy.md "Extremes").
    if (!(det > 0.0) || !(det <= double(std::numeric_limits<float>::max()))) {
        e.degenerate = true;
        return e;
    }
    FinishEllipse(det_raw, det, antialias, e);
    return e;
}

void ComputeTileRect(double x, double y, int radius, const TileGrid& grid, ProjectedSplat& splat) {
    // (int) truncates toward zero as in the CUDA code; the clamp makes that equal to floor.
    // The double is clamped first so far-away or non-finite centres cannot overflow the cast.
    auto lo = [](double v, int tiles) {
        const double t = v / kTileSize;
        if (!(t > 0.0)) return 0;
        return static_cast<int>(std::min(t, static_cast<double>(tiles)));
    };
    splat.rect_min_x = lo(x - radius, grid.tiles_x);
    splat.rect_min_y = lo(y - radius, grid.tiles_y);
    splat.rect_max_x = lo(x + radius + kTileSize - 1, grid.tiles_x);
    splat.rect_max_y = lo(y + radius + kTileSize - 1, grid.tiles_y);
}

OriginalProjection GetOriginalProjection(const camera::PinholeCamera& camera) {
    OriginalProjection m;
    m.width = camera.width;
    m.height = camera.height;
    m.centered = camera.cx == 0.5 * (camera.width - 1) && camera.cy == 0.5 * (camera.height - 1);
    const Eigen::Matrix3d r = camera.GetRotation();
    const Eigen::Vector3d t = camera.GetTranslation();
    const float sx = static_cast<float>(2.0 * camera.fx / camera.width);
    const float sy = static_cast<float>(2.0 * camera.fy / camera.height);
    for (int j = 0; j < 4; ++j) {
        const float wx = static_cast<float>(j < 3 ? r(0, j) : t.x());
        const float wy = static_cast<float>(j < 3 ? r(1, j) : t.y());
        const float wz = static_cast<float>(j < 3 ? r(2, j) : t.z());
        volatile float px = sx * wx, py = sy * wy;  // rounded to float32, never fused
        m.row_x[j] = px;
        m.row_y[j] = py;
        m.row_w[j] = wz;
    }
    return m;
}

std::array<float, 2> OriginalPixelCenter(const OriginalProjection& m, const float* p, double x,
                                         double y) {
    if (!m.centered) return {static_cast<float>(x), static_cast<float>(y)};
    auto row = [&](const float* r) {
        return shader::ReferenceViewDepth(r[0], r[1], r[2], r[3], p[0], p[1], p[2]);
    };
    const float hx = row(m.row_x), hy = row(m.row_y);
    volatile float w_guard = row(m.row_w) + 0.0000001f;
    volatile float inv_w = 1.0f / w_guard;
    volatile float ndc_x = hx * inv_w, ndc_y = hy * inv_w;
    auto to_pixel = [](float v, int size) {
        return static_cast<float>(((double(v) + 1.0) * size - 1.0) * 0.5);
    };
    return {to_pixel(ndc_x, m.width), to_pixel(ndc_y, m.height)};
}

namespace {

struct ViewParams {
    Eigen::Matrix3d rotation;  // world to camera
    Eigen::Vector3d translation;
    Eigen::Vector3d center;                  // camera centre, world space
    shader::CameraCenterSplit center_split;  // float32 high + low (the sort depth's)
    shader::ReferenceDepthRow depth_row;     // the original's float32 matrix row (its view z)
    OriginalProjection original;             // its full projection, for its float32 pixel centre
    double fx, fy, cx, cy;
    double lim_x, lim_y;                // 1.3 tan(fov / 2): the Jacobian guard band's half width
    double lim_center_x, lim_center_y;  // its centre, the image's (0 when centred)
    TileGrid grid;
};

// M = R diag(s), so the 3D covariance is M M^T, for a (w, x, y, z) quaternion normalised
// here because 3DGS normalises rotations before the rasterizer sees them. Any norm > 0
// works (a float32 subnormal squares to ~1e-90, fine in double); the zero quaternion stays
// zero and Eigen's formula makes it the identity, as the shader's does.
Eigen::Matrix3d CovarianceFactor(const float* scale, const float* rot) {
    Eigen::Quaterniond q(rot[0], rot[1], rot[2], rot[3]);
    const double norm = q.norm();
    if (norm > 0.0) q.coeffs() /= norm;
    const Eigen::Vector3d s(scale[0], scale[1], scale[2]);
    return q.toRotationMatrix() * s.asDiagonal();
}

// The float32 depth that orders and near-culls the splat, exactly as the GPU computes it.
float OrderDepth(const ViewParams& view, DepthOrder order, const float* position) {
    if (order == DepthOrder::kReference) {
        const shader::ReferenceDepthRow& m = view.depth_row;
        return shader::ReferenceViewDepth(m.m2, m.m6, m.m10, m.m14, position[0], position[1],
                                          position[2]);
    }
    const Eigen::Matrix3d& r = view.rotation;
    float rel[3];
    for (int i = 0; i < 3; ++i) {
        rel[i] = shader::CameraRelative(position[i], view.center_split.high[i],
                                        view.center_split.low[i]);
    }
    return shader::SortDepth(float(r(2, 0)), float(r(2, 1)), float(r(2, 2)), rel[0], rel[1],
                             rel[2]);
}

ProjectedSplat ProjectOne(const ViewParams& view, const RenderConfig& config, int sh_degree,
                          int64_t num_rest, const float* position, const float* scale,
                          const float* rot, float opacity_logit, const float* f_dc,
                          const float* f_rest) {
    ProjectedSplat out;
    const Eigen::Vector3d p(position[0], position[1], position[2]);
    const Eigen::Vector3d v = view.rotation * p + view.translation;
    out.depth = v.z();
    out.sort_depth = OrderDepth(view, config.depth_order, position);
    // The near cull compares the GPU's float32 depth with the float32 near plane (3DGS:
    // p_view.z <= 0.2f in float), so a splat within rounding of the plane is culled or kept
    // on every backend alike; the double z would keep a splat at 0.2f (> 0.2).
    if (!(out.sort_depth > static_cast<float>(config.near_plane))) {
        out.cull = CullReason::kNearPlane;
        return out;
    }
    out.x = view.fx * v.x() / v.z() + view.cx;
    out.y = view.fy * v.y() / v.z() + view.cy;
    // The original's float32 centre for the threshold decisions in its order; with the
    // camera-relative order (scenes far from the origin, where the original's float32
    // world-space centre is off by pixels) our own centre rounded to float32.
    const auto original = config.depth_order == DepthOrder::kReference
                              ? OriginalPixelCenter(view.original, position, out.x, out.y)
                              : std::array<float, 2>{float(out.x), float(out.y)};
    out.original_x = original[0];
    out.original_y = original[1];

    // Perspective Jacobian at the clamped position: splats far outside the view would
    // otherwise get huge, smeared footprints. The band is centred on the image, not on the
    // axis, so an off-centre principal point keeps every splat inside the image unclamped.
    const double tx =
        std::clamp(v.x() / v.z(), view.lim_center_x - view.lim_x, view.lim_center_x + view.lim_x) *
        v.z();
    const double ty =
        std::clamp(v.y() / v.z(), view.lim_center_y - view.lim_y, view.lim_center_y + view.lim_y) *
        v.z();
    Eigen::Matrix<double, 2, 3> j;
    j << view.fx / v.z(), 0.0, -view.fx * tx / (v.z() * v.z()), 0.0, view.fy / v.z(),
        -view.fy * ty / (v.z() * v.z());
    // cov2D = T Sigma T^T = U U^T with U = T M (rows u0, u1): det(cov2D) = |u0 x u1|^2
    // (Lagrange's identity) cannot cancel the way a c - b^2 does.
    const Eigen::Matrix<double, 2, 3> u = j * view.rotation * CovarianceFactor(scale, rot);
    const Eigen::Vector3d u0 = u.row(0).transpose(), u1 = u.row(1).transpose();
    const ScreenEllipse e = ComputeScreenEllipse(u0.squaredNorm(), u0.dot(u1), u1.squaredNorm(),
                                                 u0.cross(u1).squaredNorm(), config.antialias);
    out.cov_a = e.cov_a;
    out.cov_b = e.cov_b;
    out.cov_c = e.cov_c;
    if (e.degenerate) {
        out.cull = CullReason::kDegenerate;
        return out;
    }
    out.conic_a = e.conic_a;
    out.conic_b = e.conic_b;
    out.conic_c = e.conic_c;
    out.det_q = e.det_q;
    out.radius = e.radius;
    ComputeTileRect(out.x, out.y, out.radius, view.grid, out);
    if (out.NumTiles() == 0) {
        out.cull = CullReason::kNoTiles;
        return out;
    }

    const Eigen::Vector3d dir = (p - view.center).normalized();
    const auto sh = t::geometry::EvaluateSH<double>(
        sh_degree, f_dc, num_rest > 0 ? f_rest : nullptr, dir.x(), dir.y(), dir.z());
    for (int c = 0; c < 3; ++c) out.color[c] = std::max(0.0, 0.5 + sh[c]);
    out.opacity = 1.0 / (1.0 + std::exp(-static_cast<double>(opacity_logit))) * e.opacity_scale;
    out.cull = CullReason::kVisible;
    return out;
}

}  // namespace

std::pair<int, int> ProjectedSplat::RowSpan(int ty) const {
    const float t =
        shader::TileCullThreshold(float(opacity), float(conic_a), float(conic_c), float(det_q));
    const uint32_t span = shader::TileRowSpan(float(x), float(y), float(conic_a), float(conic_b),
                                              float(conic_c), float(det_q), t, uint32_t(ty),
                                              uint32_t(rect_min_x), uint32_t(rect_max_x));
    return {int(span & 0xFFFFu), int(span >> 16)};
}

int64_t ProjectedSplat::NumEntries() const {
    int64_t n = 0;
    for (int ty = rect_min_y; ty < rect_max_y; ++ty) {
        const auto [first, last] = RowSpan(ty);
        n += last - first;
    }
    return n;
}

std::vector<ProjectedSplat> ProjectSplats(const t::geometry::PointCloud& cloud,
                                          const camera::PinholeCamera& camera,
                                          const RenderConfig& config) {
    const t::geometry::GaussianSplatArrays a = cloud.GetGaussianSplatArrays();  // validates
    camera.Validate();
    ViewParams view;
    view.rotation = camera.GetRotation();
    view.translation = camera.GetTranslation();
    view.center = camera.GetCenter();
    const double center[3] = {view.center.x(), view.center.y(), view.center.z()};
    view.center_split = shader::SplitCameraCenter(center);
    view.depth_row = {float(view.rotation(2, 0)), float(view.rotation(2, 1)),
                      float(view.rotation(2, 2)), float(view.translation.z())};
    view.original = GetOriginalProjection(camera);
    view.fx = camera.fx;
    view.fy = camera.fy;
    view.cx = camera.cx;
    view.cy = camera.cy;
    view.lim_x = 1.3 * camera.GetTanHalfFovX();
    view.lim_y = 1.3 * camera.GetTanHalfFovY();
    view.lim_center_x = camera.GetImageCenterTanX();
    view.lim_center_y = camera.GetImageCenterTanY();
    view.grid = TileGrid::ForImage(camera.width, camera.height);

    const int64_t n = a.num_points;
    const int sh_degree = std::clamp(config.sh_degree, 0, a.sh_degree);
    const int64_t num_rest = a.num_rest;  // per channel
    std::vector<ProjectedSplat> out(n);
    core::ParallelFor(
        n,
        [&](int64_t i) {
            out[i] = ProjectOne(view, config, sh_degree, num_rest, a.positions + 3 * i,
                                a.scale + 3 * i, a.rot + 4 * i, a.opacity[i], a.f_dc + 3 * i,
                                a.f_rest ? a.f_rest + i * num_rest * 3 : nullptr);
        },
        4096);
    return out;
}

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
