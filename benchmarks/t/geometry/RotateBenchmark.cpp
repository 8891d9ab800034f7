// Rotating a 1M-splat degree-3 cloud: the whole PointCloud::Rotate (positions, quaternions,
// 15 SH coefficients x RGB) and the SH part alone. Goal: well under a second on 2 cores.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <random>

#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/SHRotation.h"

namespace open3d {
namespace t {
namespace geometry {
namespace {

constexpr int64_t kNumSplats = 1000000;
constexpr int kDegree = 3;

core::Tensor RandomTensor(std::mt19937& rng, const core::SizeVector& shape, float lo, float hi) {
    core::Tensor t(shape, core::Dtype::Float32);
    std::uniform_real_distribution<float> uniform(lo, hi);
    float* p = t.Data<float>();
    for (int64_t i = 0; i < t.NumElements(); ++i) p[i] = uniform(rng);
    return t;
}

PointCloud MakeCloud() {
    std::mt19937 rng(7);
    const int64_t n = kNumSplats;
    PointCloud cloud(RandomTensor(rng, {n, 3}, -10.f, 10.f));
    cloud.SetPointAttr(gs_attr::kScale, RandomTensor(rng, {n, 3}, 0.01f, 1.f));
    // Unnormalised quaternions are fine here: the cost does not depend on the values.
    cloud.SetPointAttr(gs_attr::kRot, RandomTensor(rng, {n, 4}, -1.f, 1.f));
    cloud.SetPointAttr(gs_attr::kOpacity, RandomTensor(rng, {n, 1}, -3.f, 3.f));
    cloud.SetPointAttr(gs_attr::kFDc, RandomTensor(rng, {n, 3}, -1.f, 1.f));
    cloud.SetPointAttr(gs_attr::kFRest,
                       RandomTensor(rng, {n, NumSHRestCoeffs(kDegree), 3}, -1.f, 1.f));
    return cloud;
}

// A fixed, non-trivial rotation (not the identity, which Rotate short-cuts for SH).
Eigen::Matrix3d TestRotation() {
    return Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
}

void BM_RotateSplatCloud1M(benchmark::State& state) {
    PointCloud cloud = MakeCloud();
    const Eigen::Matrix3d R = TestRotation();
    const Eigen::Vector3d center = cloud.GetCenter();
    for (auto _ : state) {
        cloud.Rotate(R, center);
        benchmark::DoNotOptimize(cloud.GetPointPositions().RawData());
    }
    state.SetItemsProcessed(state.iterations() * kNumSplats);
}
BENCHMARK(BM_RotateSplatCloud1M)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RotateSHRest1M(benchmark::State& state) {
    PointCloud cloud = MakeCloud();
    float* f_rest = cloud.GetPointAttr(gs_attr::kFRest).Data<float>();
    const Eigen::Matrix3d R = TestRotation();
    for (auto _ : state) {
        // Band matrices are rebuilt every call, as Rotate does.
        RotateSHRest(SHRotation(R, kDegree), kNumSplats, f_rest);
        benchmark::DoNotOptimize(f_rest);
    }
    state.SetItemsProcessed(state.iterations() * kNumSplats);
}
BENCHMARK(BM_RotateSHRest1M)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ScaleNegative1M(benchmark::State& state) {
    PointCloud cloud = MakeCloud();
    const Eigen::Vector3d center = cloud.GetCenter();
    for (auto _ : state) {
        cloud.Scale(-1.0, center);  // |s| = 1 keeps the data bounded across iterations
        benchmark::DoNotOptimize(cloud.GetPointPositions().RawData());
    }
    state.SetItemsProcessed(state.iterations() * kNumSplats);
}
BENCHMARK(BM_ScaleNegative1M)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace geometry
}  // namespace t
}  // namespace open3d

BENCHMARK_MAIN();
