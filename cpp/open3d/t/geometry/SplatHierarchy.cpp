#include "open3d/t/geometry/SplatHierarchy.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numeric>
#include <queue>
#include <utility>

#include "open3d/core/Exception.h"
#include "open3d/core/Progress.h"

namespace open3d {
namespace t {
namespace geometry {

namespace {

constexpr int kMortonBits = 21;  // per axis: 63 bits of code
constexpr int kMaxChildren = 8;
// Merged opacities stay inside (0, 1) so that their logit is finite.
constexpr double kMinAlpha = 1e-6, kMaxAlpha = 0.99;

// Bits of `v` (21 bits) spread to every third position.
uint64_t Spread3(uint64_t v) {
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
}

// One node's Gaussian in double precision: what merging reads and writes.
struct Gaussian {
    Eigen::Vector3d mean;
    Eigen::Matrix3d covariance;
    Eigen::Vector3d scale;  // sorted descending
    Eigen::Matrix3d axes;   // merged nodes: the covariance's eigenvectors, largest first
    double alpha = 0.0;
    std::vector<double> color;  // f_dc then f_rest, flattened
};

double Sigmoid(double x) { return 1.0 / (1.0 + std::exp(-x)); }

class Builder {
public:
    explicit Builder(const PointCloud& splats) : a_(splats.GetGaussianSplatArrays()) {
        color_size_ = 3 + 3 * a_.num_rest;
        hierarchy_.num_leaves = a_.num_points;
    }

    SplatHierarchy Build() {
        const int64_t n = a_.num_points;
        std::vector<uint64_t> codes(n);
        Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY);
        Eigen::Vector3d hi = -lo;
        for (int64_t i = 0; i < n; ++i) {
            const Eigen::Vector3d p = Position(i);
            lo = lo.cwiseMin(p);
            hi = hi.cwiseMax(p);
        }
        const double extent = std::max((hi - lo).maxCoeff(), 1e-30);
        const double cells = double((1u << kMortonBits) - 1);
        for (int64_t i = 0; i < n; ++i) {
            const Eigen::Vector3d u = (Position(i) - lo) / extent * cells;
            uint64_t code = 0;
            for (int axis = 0; axis < 3; ++axis) {
                const uint64_t q = static_cast<uint64_t>(std::clamp(u[axis], 0.0, cells));
                code |= Spread3(q) << (2 - axis);
            }
            codes[i] = code;
        }
        order_.resize(n);
        std::iota(order_.begin(), order_.end(), 0);
        std::stable_sort(order_.begin(), order_.end(),
                         [&](int64_t x, int64_t y) { return codes[x] < codes[y]; });
        codes_.resize(n);
        for (int64_t i = 0; i < n; ++i) codes_[i] = codes[order_[i]];
        BuildRange(0, n, kMortonBits - 1);
        core::ReportProgress(kStage, 1.0);
        Finish();
        return std::move(hierarchy_);
    }

private:
    Eigen::Vector3d Position(int64_t i) const {
        const float* p = a_.positions + 3 * i;
        return Eigen::Vector3d(p[0], p[1], p[2]);
    }

    Gaussian Leaf(int64_t i) const {
        Gaussian g;
        g.mean = Position(i);
        const float* s = a_.scale + 3 * i;
        const float* q = a_.rot + 4 * i;
        const Eigen::Matrix3d r =
            Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
        const Eigen::Vector3d s2(double(s[0]) * s[0], double(s[1]) * s[1], double(s[2]) * s[2]);
        g.covariance = r * s2.asDiagonal() * r.transpose();
        g.scale = Eigen::Vector3d(s[0], s[1], s[2]).cwiseAbs();
        std::sort(g.scale.data(), g.scale.data() + 3, std::greater<double>());
        g.alpha = Sigmoid(a_.opacity[i]);
        g.color.resize(color_size_);
        for (int c = 0; c < 3; ++c) g.color[c] = a_.f_dc[3 * i + c];
        for (int k = 0; k < 3 * a_.num_rest; ++k)
            g.color[3 + k] = a_.f_rest[3 * a_.num_rest * i + k];
        return g;
    }

    Gaussian Node(int64_t id) const {
        return id < hierarchy_.num_leaves ? Leaf(id) : inner_[id - hierarchy_.num_leaves];
    }

    // Moment matching of the children (docs/lod.md "Merging").
    Gaussian Merge(const std::vector<int64_t>& children) {
        std::vector<Gaussian> parts;
        for (int64_t c : children) parts.push_back(Node(c));
        std::vector<double> weights;
        for (const Gaussian& g : parts) weights.push_back(g.alpha * g.scale.prod());
        double total = std::accumulate(weights.begin(), weights.end(), 0.0);
        if (!(total > 0.0)) {  // degenerate (flat or transparent) children: equal weights
            std::fill(weights.begin(), weights.end(), 1.0);
            total = double(weights.size());
        }
        Gaussian m;
        m.mean.setZero();
        m.color.assign(color_size_, 0.0);
        for (size_t j = 0; j < parts.size(); ++j) {
            const double w = weights[j] / total;
            m.mean += w * parts[j].mean;
            for (int k = 0; k < color_size_; ++k) m.color[k] += w * parts[j].color[k];
        }
        m.covariance.setZero();
        for (size_t j = 0; j < parts.size(); ++j) {
            const Eigen::Vector3d d = parts[j].mean - m.mean;
            m.covariance += weights[j] / total * (parts[j].covariance + d * d.transpose());
        }
        m.covariance = 0.5 * (m.covariance + m.covariance.transpose());
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(m.covariance);
        const Eigen::Vector3d values = eigen.eigenvalues().cwiseMax(0.0);
        m.scale = Eigen::Vector3d(std::sqrt(values[2]), std::sqrt(values[1]), std::sqrt(values[0]));
        m.axes = eigen.eigenvectors().rowwise().reverse();  // columns largest first, as scale
        const double area = m.scale[0] * m.scale[1];
        double transmitted = 1.0;
        for (const Gaussian& g : parts) {
            const double share = area > 0.0 ? std::min(1.0, g.scale[0] * g.scale[1] / area) : 1.0;
            transmitted *= 1.0 - g.alpha * share;
        }
        m.alpha = std::clamp(1.0 - transmitted, kMinAlpha, kMaxAlpha);
        return m;
    }

    int64_t AddInner(const std::vector<int64_t>& children) {
        inner_.push_back(Merge(children));
        hierarchy_.children.insert(hierarchy_.children.end(), children.begin(), children.end());
        hierarchy_.child_offsets.push_back(static_cast<int64_t>(hierarchy_.children.size()));
        return hierarchy_.num_leaves + static_cast<int64_t>(inner_.size()) - 1;
    }

    // Leaves are placed left to right: their count is the progress.
    int64_t PlaceLeaf(int64_t i) {
        if (++placed_ % kProgressStep == 0) {
            core::ReportProgress(kStage, double(placed_) / double(hierarchy_.num_leaves));
        }
        return order_[i];
    }

    // Splats order_[b, e) that share their code above bit group `level`; returns the node.
    int64_t BuildRange(int64_t b, int64_t e, int level) {
        if (e - b == 1) return PlaceLeaf(b);
        if (level < 0) return GroupEqual(b, e);  // identical codes
        std::vector<int64_t> children;
        int64_t start = b;
        const auto octant = [&](int64_t i) { return (codes_[i] >> (3 * level)) & 7u; };
        for (int64_t i = b + 1; i <= e; ++i) {
            if (i == e || octant(i) != octant(start)) {
                children.push_back(start);
                start = i;
            }
        }
        if (children.size() == 1) return BuildRange(b, e, level - 1);
        std::vector<int64_t> nodes;
        for (size_t c = 0; c < children.size(); ++c) {
            const int64_t end = c + 1 < children.size() ? children[c + 1] : e;
            nodes.push_back(BuildRange(children[c], end, level - 1));
        }
        return AddInner(nodes);
    }

    // Splats with one Morton code, eight (or fewer) to a node, nodes grouped likewise.
    int64_t GroupEqual(int64_t b, int64_t e) {
        std::vector<int64_t> nodes;
        for (int64_t i = b; i < e; ++i) nodes.push_back(PlaceLeaf(i));
        while (nodes.size() > 1) {
            std::vector<int64_t> up;
            for (size_t i = 0; i < nodes.size(); i += kMaxChildren) {
                const size_t end = std::min(nodes.size(), i + kMaxChildren);
                if (end - i == 1) {
                    up.push_back(nodes[i]);
                } else {
                    up.push_back(AddInner({nodes.begin() + i, nodes.begin() + end}));
                }
            }
            nodes = std::move(up);
        }
        return nodes[0];
    }

    // The inner nodes' Gaussians as a cloud with the source's attributes.
    void Finish() {
        const int64_t k = static_cast<int64_t>(inner_.size());
        core::Tensor positions({k, 3}, core::Dtype::Float32);
        core::Tensor scale({k, 3}, core::Dtype::Float32);
        core::Tensor rot({k, 4}, core::Dtype::Float32);
        core::Tensor opacity({k, 1}, core::Dtype::Float32);
        core::Tensor f_dc({k, 3}, core::Dtype::Float32);
        core::Tensor f_rest({k, a_.num_rest, 3}, core::Dtype::Float32);
        for (int64_t j = 0; j < k; ++j) {
            const Gaussian& g = inner_[j];
            Eigen::Matrix3d axes = g.axes;  // a proper rotation: flip the smallest axis
            if (axes.determinant() < 0.0) axes.col(2) *= -1.0;
            Eigen::Quaterniond q(axes);
            q.normalize();
            if (q.w() < 0.0) q.coeffs() *= -1.0;
            const float values[] = {float(q.w()), float(q.x()), float(q.y()), float(q.z())};
            std::copy(values, values + 4, rot.Data<float>() + 4 * j);
            for (int c = 0; c < 3; ++c) {
                positions.Data<float>()[3 * j + c] = float(g.mean[c]);
                scale.Data<float>()[3 * j + c] = float(g.scale[c]);
                f_dc.Data<float>()[3 * j + c] = float(g.color[c]);
            }
            for (int r = 0; r < 3 * a_.num_rest; ++r) {
                f_rest.Data<float>()[3 * a_.num_rest * j + r] = float(g.color[3 + r]);
            }
            opacity.Data<float>()[j] = float(std::log(g.alpha / (1.0 - g.alpha)));
        }
        PointCloud cloud(positions);
        cloud.SetPointAttr(gs_attr::kScale, scale);
        cloud.SetPointAttr(gs_attr::kRot, rot);
        cloud.SetPointAttr(gs_attr::kOpacity, opacity);
        cloud.SetPointAttr(gs_attr::kFDc, f_dc);
        if (a_.num_rest > 0) cloud.SetPointAttr(gs_attr::kFRest, f_rest);
        hierarchy_.inner = std::move(cloud);
    }

    GaussianSplatArrays a_;
    int color_size_ = 3;
    SplatHierarchy hierarchy_;
    std::vector<int64_t> order_;
    std::vector<uint64_t> codes_;  // in order_
    std::vector<Gaussian> inner_;
    int64_t placed_ = 0;  // leaves placed in the tree so far
    static constexpr const char* kStage = "level of detail";
    static constexpr int64_t kProgressStep = int64_t(1) << 16;
};

// The inner nodes' attribute arrays (none for a hierarchy of one splat).
GaussianSplatArrays InnerArrays(const SplatHierarchy& hierarchy) {
    return hierarchy.inner.IsEmpty() ? GaussianSplatArrays{}
                                     : hierarchy.inner.GetGaussianSplatArrays();
}

}  // namespace

// Whether a sphere of `radius` about camera-space point `c` lies wholly behind the camera
// or, where the view has an image, wholly outside one of its frustum's four side planes,
// widened like the renderer's guard band: splats up to 1.3x the half-angle out are still
// projected, and the footprint's 0.3 px dilation reaches 1.6 px beyond the ellipse
// (docs/lod.md "Cut").
bool SplatOutsideView(const SplatCutView& view, const Eigen::Vector3d& c, double radius) {
    if (c.z() + radius <= 0.0) return true;
    if (view.width <= 0 || view.height <= 0) return false;
    // x / z on the image lies in [lo, hi], widened by 15% of the span and 2 px each side;
    // the plane x = m z is at signed distance (x - m z) / sqrt(1 + m^2) from c.
    const auto outside = [&](double x, double lo, double hi, double f) {
        const double margin = 0.15 * (hi - lo) + 2.0 / f;
        lo -= margin;
        hi += margin;
        return (x - lo * c.z()) / std::sqrt(1.0 + lo * lo) < -radius ||
               (hi * c.z() - x) / std::sqrt(1.0 + hi * hi) < -radius;
    };
    return outside(c.x(), (-0.5 - view.cx) / view.fx, (view.width - 0.5 - view.cx) / view.fx,
                   view.fx) ||
           outside(c.y(), (-0.5 - view.cy) / view.fy, (view.height - 0.5 - view.cy) / view.fy,
                   view.fy);
}

uint64_t SplatSceneFingerprint(const PointCloud& splats) {
    const GaussianSplatArrays a = splats.GetGaussianSplatArrays();
    // One multiply-rotate step per 32-bit word: order-sensitive, ~1 ns a word.
    uint64_t h = 0x243F6A8885A308D3ull;
    const auto mix = [&h](uint64_t word) {
        h = ((h << 27) | (h >> 37)) ^ word;
        h *= 0x9E3779B97F4A7C15ull;
    };
    mix(static_cast<uint64_t>(a.num_points));
    mix(static_cast<uint64_t>(a.sh_degree));
    const auto mix_floats = [&mix](const float* values, int64_t count) {
        for (int64_t i = 0; i < count; ++i) {
            uint32_t bits = 0;
            std::memcpy(&bits, values + i, 4);
            mix(bits);
        }
    };
    mix_floats(a.positions, 3 * a.num_points);
    mix_floats(a.opacity, a.num_points);
    return h == 0 ? 1 : h;  // 0 means "unknown"
}

std::string HierarchySourceMismatch(const SplatHierarchy& hierarchy, const PointCloud& source) {
    const int64_t n = source.IsEmpty() ? 0 : source.NumPoints();
    if (hierarchy.num_leaves != n) {
        return fmt::format("it has {} leaves and the scene {} splats", hierarchy.num_leaves, n);
    }
    if (hierarchy.NumInner() > 0) {
        const int inner_degree = hierarchy.inner.GaussianSplatGetSHOrder();
        const int degree = source.GaussianSplatGetSHOrder();
        if (inner_degree != degree) {
            return fmt::format("its nodes have SH degree {} and the scene's splats {}",
                               inner_degree, degree);
        }
    }
    if (hierarchy.scene_fingerprint != 0 &&
        hierarchy.scene_fingerprint != SplatSceneFingerprint(source)) {
        return fmt::format(
            "it was built from another scene of {} splats (the positions or opacities differ)", n);
    }
    return "";
}

SplatHierarchy BuildSplatHierarchy(const PointCloud& splats) {
    if (splats.IsEmpty()) core::ThrowError("BuildSplatHierarchy: the cloud has no splat");
    SplatHierarchy hierarchy = Builder(splats).Build();
    hierarchy.scene_fingerprint = SplatSceneFingerprint(splats);
    return hierarchy;
}

std::vector<int64_t> CutSplatHierarchy(const SplatHierarchy& hierarchy, const SplatCutView& view,
                                       int64_t budget) {
    if (budget < 1) core::ThrowError("CutSplatHierarchy: the budget must be >= 1, not {}", budget);
    const Eigen::Matrix3d r = view.world_to_camera.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = view.world_to_camera.topRightCorner<3, 1>();
    const GaussianSplatArrays inner = InnerArrays(hierarchy);
    // Projected size of inner node k: 3 sigma of its largest axis over its depth; a node
    // nearer than its own size counts as its size in pixels times a large factor.
    // A node wholly outside the view (SplatOutsideView) gets -1: it is opened only after every
    // node in view, where the budget still allows (so a budget of every leaf stays exact).
    const auto size = [&](int64_t k) {
        const float* p = inner.positions + 3 * k;
        const float* s = inner.scale + 3 * k;
        const double radius = 3.0 * std::max({std::abs(s[0]), std::abs(s[1]), std::abs(s[2])});
        const Eigen::Vector3d c = r * Eigen::Vector3d(p[0], p[1], p[2]) + t;
        if (SplatOutsideView(view, c, radius)) return -1.0;
        return view.focal_px * radius / std::max(c.z(), 1e-3 * radius + 1e-30);
    };
    std::vector<int64_t> cut;
    std::priority_queue<std::pair<double, int64_t>> open;  // (size, inner index)
    const auto add = [&](int64_t node) {
        if (node < hierarchy.num_leaves) {
            cut.push_back(node);
        } else {
            const int64_t k = node - hierarchy.num_leaves;
            open.push({size(k), k});
        }
    };
    add(hierarchy.Root());
    int64_t count = 1;  // nodes in cut and open
    while (!open.empty()) {
        const int64_t k = open.top().second;
        open.pop();
        const int64_t children = hierarchy.child_offsets[k + 1] - hierarchy.child_offsets[k];
        if (count - 1 + children > budget) {
            cut.push_back(hierarchy.num_leaves + k);  // stays whole
            continue;
        }
        count += children - 1;
        for (int64_t c = hierarchy.child_offsets[k]; c < hierarchy.child_offsets[k + 1]; ++c) {
            add(hierarchy.children[c]);
        }
    }
    std::sort(cut.begin(), cut.end());
    return cut;
}

PointCloud ExtractSplatNodes(const SplatHierarchy& hierarchy, const PointCloud& source,
                             const std::vector<int64_t>& nodes) {
    const std::string mismatch = HierarchySourceMismatch(hierarchy, source);
    if (!mismatch.empty()) {
        core::ThrowError("ExtractSplatNodes: the hierarchy does not fit its source: {}", mismatch);
    }
    const GaussianSplatArrays leaves = source.GetGaussianSplatArrays();
    const GaussianSplatArrays inner = InnerArrays(hierarchy);
    const int64_t n = static_cast<int64_t>(nodes.size());
    const int rest = leaves.num_rest;
    struct Column {
        const char* name;
        int64_t width;
        const float* GaussianSplatArrays::*array;
    };
    const Column columns[] = {{gs_attr::kPositions, 3, &GaussianSplatArrays::positions},
                              {gs_attr::kScale, 3, &GaussianSplatArrays::scale},
                              {gs_attr::kRot, 4, &GaussianSplatArrays::rot},
                              {gs_attr::kOpacity, 1, &GaussianSplatArrays::opacity},
                              {gs_attr::kFDc, 3, &GaussianSplatArrays::f_dc},
                              {gs_attr::kFRest, 3 * rest, &GaussianSplatArrays::f_rest}};
    PointCloud out;
    for (const Column& column : columns) {
        if (column.width == 0) continue;  // no f_rest at SH degree 0
        const core::Tensor& like = source.GetPointAttr(column.name);
        core::SizeVector shape = like.GetShape();
        shape[0] = n;
        core::Tensor values(shape, core::Dtype::Float32);
        for (int64_t j = 0; j < n; ++j) {
            const int64_t node = nodes[j];
            if (node < 0 || node >= hierarchy.NumNodes()) {
                core::ThrowError("ExtractSplatNodes: node {} is not in the hierarchy ({} nodes)",
                                 node, hierarchy.NumNodes());
            }
            const bool leaf = node < hierarchy.num_leaves;
            const float* from =
                leaf ? leaves.*column.array + column.width * node
                     : inner.*column.array + column.width * (node - hierarchy.num_leaves);
            std::copy(from, from + column.width, values.Data<float>() + column.width * j);
        }
        if (column.array == &GaussianSplatArrays::positions) {
            out = PointCloud(values);
        } else {
            out.SetPointAttr(column.name, values);
        }
    }
    return out;
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
