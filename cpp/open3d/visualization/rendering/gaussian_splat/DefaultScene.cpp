#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "open3d/t/geometry/SphericalHarmonics.h"

namespace open3d {
namespace visualization {
namespace rendering {

namespace {

constexpr int kRest = 15;  // (3 + 1)^2 - 1 coefficients per channel

// Accumulates splats in the attribute layout of t::geometry::PointCloud.
class SceneBuilder {
public:
    /// `axes` columns are the splat's local axes; `scale` is along them (linear units).
    void Add(const Eigen::Vector3d& position, const Eigen::Matrix3d& axes,
             const Eigen::Vector3d& scale, double opacity, const Eigen::Vector3d& color,
             const std::vector<std::pair<int, Eigen::Vector3d>>& sh_rest = {}) {
        for (int i = 0; i < 3; ++i) {
            positions_.push_back(static_cast<float>(position[i]));
            scales_.push_back(static_cast<float>(scale[i]));
            f_dc_.push_back(static_cast<float>((color[i] - 0.5) / t::geometry::kSH_C0));
        }
        const Eigen::Quaterniond q(axes);
        for (double v : {q.w(), q.x(), q.y(), q.z()}) rots_.push_back(static_cast<float>(v));
        opacities_.push_back(static_cast<float>(std::log(opacity / (1.0 - opacity))));
        const size_t base = f_rest_.size();
        f_rest_.resize(base + kRest * 3, 0.f);
        for (const auto& [k, rgb] : sh_rest) {
            for (int c = 0; c < 3; ++c) f_rest_[base + k * 3 + c] = static_cast<float>(rgb[c]);
        }
    }

    t::geometry::PointCloud Build() const {
        namespace gs = t::geometry::gs_attr;
        const int64_t n = static_cast<int64_t>(opacities_.size());
        t::geometry::PointCloud cloud(core::Tensor::FromVector(positions_, {n, 3}));
        cloud.SetPointAttr(gs::kScale, core::Tensor::FromVector(scales_, {n, 3}));
        cloud.SetPointAttr(gs::kRot, core::Tensor::FromVector(rots_, {n, 4}));
        cloud.SetPointAttr(gs::kOpacity, core::Tensor::FromVector(opacities_, {n, 1}));
        cloud.SetPointAttr(gs::kFDc, core::Tensor::FromVector(f_dc_, {n, 3}));
        cloud.SetPointAttr(gs::kFRest, core::Tensor::FromVector(f_rest_, {n, kRest, 3}));
        return cloud;
    }

private:
    std::vector<float> positions_, scales_, rots_, opacities_, f_dc_, f_rest_;
};

// Deterministic jitter in [-1, 1) from an index (splitmix64), portable across libraries.
double Jitter(uint64_t i) {
    uint64_t z = i * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) / static_cast<double>(1ull << 52) - 1.0;
}

// A right-handed frame whose third column is `normal`.
Eigen::Matrix3d FrameFromNormal(const Eigen::Vector3d& normal) {
    const Eigen::Vector3d n = normal.normalized();
    const Eigen::Vector3d helper =
        std::abs(n.y()) < 0.9 ? Eigen::Vector3d(0, 1, 0) : Eigen::Vector3d(1, 0, 0);
    const Eigen::Vector3d t1 = helper.cross(n).normalized();
    Eigen::Matrix3d axes;
    axes << t1, n.cross(t1), n;
    return axes;
}

void AddGround(SceneBuilder& scene) {
    constexpr double kRadius = 2.6, kStep = 0.09;
    uint64_t id = 0;
    for (double x = -kRadius; x <= kRadius; x += kStep) {
        for (double z = -kRadius; z <= kRadius; z += kStep, ++id) {
            const double r = std::hypot(x, z);
            if (r > kRadius) continue;
            const bool dark =
                (static_cast<int>(std::floor(x / 0.5)) + static_cast<int>(std::floor(z / 0.5))) %
                    2 !=
                0;
            const double shade = (dark ? 0.32 : 0.78) * (1.0 - 0.25 * r / kRadius);
            const Eigen::Vector3d color(shade, shade * 0.97, shade * 0.92);
            const Eigen::Vector3d pos(x + 0.02 * Jitter(id), 0.0, z + 0.02 * Jitter(id + 7919));
            // Flat along y, slightly elongated along a varying direction: anisotropic.
            const double yaw = 0.3 * Jitter(id + 104729);
            Eigen::Matrix3d axes = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).matrix();
            scene.Add(pos, axes, {0.05, 0.003, 0.035}, 0.95, color);
        }
    }
}

void AddSphere(SceneBuilder& scene) {
    constexpr int kCount = 1300;
    const Eigen::Vector3d center(0.0, 0.95, 0.0);
    constexpr double kRadius = 0.85;
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < kCount; ++i) {
        const double y = 1.0 - 2.0 * (i + 0.5) / kCount;
        const double ring = std::sqrt(1.0 - y * y);
        const Eigen::Vector3d n(std::cos(golden * i) * ring, y, std::sin(golden * i) * ring);
        // Latitude gradient from teal (bottom) to magenta (top).
        const double u = 0.5 * (y + 1.0);
        const Eigen::Vector3d color(0.15 + 0.7 * u, 0.55 - 0.3 * u, 0.65 - 0.1 * u);
        // View-dependent sheen: degree 1 shifts red with the view's x, degree 2 and 3 add
        // a lobe pattern, so the sphere changes colour as the camera orbits.
        const std::vector<std::pair<int, Eigen::Vector3d>> sh = {
            {2, Eigen::Vector3d(-0.35, 0.0, 0.2)},    // basis 3: -C1 x
            {0, Eigen::Vector3d(0.0, -0.25, 0.15)},   // basis 1: -C1 y
            {4, Eigen::Vector3d(0.2, 0.2, -0.2)},     // basis 5: yz
            {8, Eigen::Vector3d(0.0, 0.25, 0.25)},    // basis 9: degree 3, m = -3
            {14, Eigen::Vector3d(0.3, -0.15, 0.0)}};  // basis 15: degree 3, m = +3
        scene.Add(center + kRadius * n, FrameFromNormal(n), {0.075, 0.06, 0.008}, 0.97, color, sh);
    }
}

void AddRing(SceneBuilder& scene) {
    constexpr int kAround = 160, kTube = 4;
    constexpr double kMajor = 1.45, kMinor = 0.1;
    const Eigen::Matrix3d tilt = Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitX()).matrix();
    const Eigen::Vector3d center(0.0, 0.95, 0.0);
    for (int i = 0; i < kAround; ++i) {
        const double a = 2.0 * std::numbers::pi * i / kAround;
        const Eigen::Vector3d radial(std::cos(a), 0.0, std::sin(a));
        const Eigen::Vector3d tangent(-std::sin(a), 0.0, std::cos(a));
        for (int j = 0; j < kTube; ++j) {
            const double b = 2.0 * std::numbers::pi * (j + 0.5 * (i % 2)) / kTube;
            const Eigen::Vector3d offset =
                kMinor * (std::cos(b) * radial + std::sin(b) * Eigen::Vector3d::UnitY());
            const Eigen::Vector3d pos = center + tilt * (kMajor * radial + offset);
            // Long along the tube's tangent: strongly anisotropic, half transparent.
            Eigen::Matrix3d axes;
            const Eigen::Vector3d t = tilt * tangent;
            const Eigen::Vector3d o = (tilt * offset).normalized();
            axes << t, o.cross(t), o;
            const double warm = 0.5 + 0.5 * std::cos(3.0 * a);
            const Eigen::Vector3d color(0.95, 0.65 + 0.2 * warm, 0.2 + 0.3 * (1.0 - warm));
            scene.Add(pos, axes, {0.05, 0.025, 0.02}, 0.45, color,
                      {{1, Eigen::Vector3d(0.2, 0.1, -0.1)}, {6, Eigen::Vector3d(0.0, 0.2, 0.3)}});
        }
    }
}

}  // namespace

t::geometry::PointCloud CreateDefaultGaussianSplatScene() {
    SceneBuilder scene;
    AddGround(scene);
    AddSphere(scene);
    AddRing(scene);
    return scene.Build();
}

camera::LookAtCamera GetDefaultSceneLookAt() {
    camera::LookAtCamera look_at;
    look_at.eye = Eigen::Vector3d(0.0, 2.3, 4.4);
    look_at.center = Eigen::Vector3d(0.0, 0.75, 0.0);
    look_at.up = Eigen::Vector3d(0.0, 1.0, 0.0);
    look_at.vertical_fov_deg = 45.0;
    return look_at;
}

camera::PinholeCamera GetDefaultSceneCamera(int width, int height) {
    return camera::PinholeCamera::FromLookAt(GetDefaultSceneLookAt(), width, height);
}

DefaultSceneMeshSphere GetDefaultSceneMeshSphere() {
    return {Eigen::Vector3d(1.05, 0.4, 0.75), 0.4};
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
