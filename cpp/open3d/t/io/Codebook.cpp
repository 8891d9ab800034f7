#include "open3d/t/io/Codebook.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <unordered_map>

#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/core/Progress.h"
#include "open3d/t/io/SogLayout.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using namespace sog;

struct RowHash {
    const float* data;
    int dims;
    size_t operator()(int64_t row) const {
        uint64_t h = 1469598103934665603ull;
        const auto* bytes = reinterpret_cast<const uint8_t*>(data + row * dims);
        for (int b = 0; b < dims * 4; ++b) h = (h ^ bytes[b]) * 1099511628211ull;
        return static_cast<size_t>(h);
    }
};
struct RowEqual {
    const float* data;
    int dims;
    bool operator()(int64_t a, int64_t b) const {
        return std::memcmp(data + a * dims, data + b * dims, size_t(dims) * 4) == 0;
    }
};

}  // namespace

std::vector<float> Quantise1D(const std::vector<float>& values, std::vector<uint8_t>& labels,
                              const std::vector<float>& weights, int iterations) {
    const size_t n = values.size();
    if (!weights.empty() && weights.size() != n) {
        core::ThrowError("Quantise1D: {} weights for {} values", weights.size(), n);
    }
    // Values in ascending order with their weights (1 each when none are given).
    std::vector<uint32_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = uint32_t(i);
    std::sort(order.begin(), order.end(),
              [&](uint32_t a, uint32_t b) { return values[a] < values[b]; });
    std::vector<float> sorted(n);
    for (size_t i = 0; i < n; ++i) sorted[i] = values[order[i]];
    std::vector<float> distinct = sorted;
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    std::vector<float> codebook;
    if (distinct.size() <= size_t(kCodebookSize)) {
        codebook = distinct;
    } else {
        // Prefix sums of w and w * v over the sorted values: a cluster's weighted mean is
        // two differences, so a Lloyd iteration costs 256 binary searches.
        std::vector<double> weight_prefix(n + 1, 0.0), moment_prefix(n + 1, 0.0);
        for (size_t i = 0; i < n; ++i) {
            const double w = weights.empty() ? 1.0 : double(weights[order[i]]);
            weight_prefix[i + 1] = weight_prefix[i] + w;
            moment_prefix[i + 1] = moment_prefix[i] + w * sorted[i];
        }
        // Seeds at the weighted quantiles (the plain quantiles without weights).
        std::vector<double> c(kCodebookSize);
        for (int k = 0; k < kCodebookSize; ++k) {
            const double target = weight_prefix[n] * (2 * k + 1) / (2.0 * kCodebookSize);
            const size_t at =
                std::upper_bound(weight_prefix.begin() + 1, weight_prefix.end(), target) -
                (weight_prefix.begin() + 1);
            c[k] = sorted[std::min(at, n - 1)];
        }
        std::vector<size_t> bounds(kCodebookSize + 1);
        for (int it = 0; it < iterations; ++it) {
            bounds[0] = 0;
            bounds[kCodebookSize] = n;
            for (int k = 1; k < kCodebookSize; ++k) {
                const double mid = 0.5 * (c[k - 1] + c[k]);
                bounds[k] = std::lower_bound(sorted.begin(), sorted.end(), mid) - sorted.begin();
                bounds[k] = std::max(bounds[k], bounds[k - 1]);
            }
            bool changed = false;
            for (int k = 0; k < kCodebookSize; ++k) {
                const double w = weight_prefix[bounds[k + 1]] - weight_prefix[bounds[k]];
                if (bounds[k + 1] == bounds[k] || !(w > 0.0)) continue;  // empty: keep it
                const double mean = (moment_prefix[bounds[k + 1]] - moment_prefix[bounds[k]]) / w;
                changed = changed || mean != c[k];
                c[k] = mean;
            }
            std::sort(c.begin(), c.end());
            if (!changed) break;
        }
        for (double v : c) codebook.push_back(static_cast<float>(v));
        std::sort(codebook.begin(), codebook.end());
    }
    codebook.resize(kCodebookSize, codebook.empty() ? 0.0f : codebook.back());
    labels.resize(values.size());
    core::ParallelFor(int64_t(values.size()), [&](int64_t i) {
        const float v = values[i];
        // First entry not below v, then the nearer of it and its predecessor.
        int k = int(std::lower_bound(codebook.begin(), codebook.end(), v) - codebook.begin());
        if (k == kCodebookSize) k = kCodebookSize - 1;
        if (k > 0 && double(v) - codebook[k - 1] <= double(codebook[k]) - v) --k;
        labels[i] = static_cast<uint8_t>(k);
    });
    return codebook;
}

std::vector<float> Palette(const float* rows, int64_t n, int dims, std::vector<int32_t>& labels) {
    constexpr int kIterations = 4;
    constexpr int64_t kSample = 32768;
    constexpr double kBudget = 1.5e10;  // about 6-8 s on two cores with the kernel below
    labels.assign(n, 0);
    std::unordered_map<int64_t, int32_t, RowHash, RowEqual> index(16, RowHash{rows, dims},
                                                                  RowEqual{rows, dims});
    std::vector<int64_t> distinct;
    for (int64_t i = 0; i < n; ++i) {
        const auto [it, inserted] = index.emplace(i, int32_t(distinct.size()));
        if (inserted) distinct.push_back(i);
        labels[i] = it->second;
    }
    if (distinct.size() <= size_t(kMaxPalette)) {
        std::vector<float> palette(distinct.size() * dims);
        for (size_t p = 0; p < distinct.size(); ++p) {
            std::copy_n(rows + distinct[p] * dims, dims, palette.begin() + p * dims);
        }
        return palette;
    }
    const int64_t sample_size = std::min(n, kSample);
    const int64_t k_budget =
        int64_t(kBudget / (double(dims) * (double(sample_size) * kIterations + double(n))));
    int64_t k = 256;
    while (k * 2 <= std::min<int64_t>(k_budget, kMaxPalette)) k *= 2;
    std::mt19937_64 rng(0x5065C0DEull);
    const auto shuffle_front = [&rng](std::vector<int64_t>& v, int64_t m) {
        for (int64_t p = 0; p < m; ++p) {
            std::uniform_int_distribution<int64_t> pick(p, int64_t(v.size()) - 1);
            std::swap(v[p], v[pick(rng)]);
        }
    };
    shuffle_front(distinct, k);
    std::vector<int64_t> sample(n);
    for (int64_t i = 0; i < n; ++i) sample[i] = i;
    shuffle_front(sample, sample_size);
    sample.resize(sample_size);
    std::sort(sample.begin(), sample.end());
    // Transposed palette [dims][k]: the distance loop then runs over centroids, which the
    // compiler vectorises (a float sum over dims would not be, without reassociation).
    std::vector<float> columns(k * dims);
    for (int64_t p = 0; p < k; ++p) {
        for (int j = 0; j < dims; ++j) columns[j * k + p] = rows[distinct[p] * dims + j];
    }
    // Nearest centroid of rows[which(i)] into label(i), for i in [0, m).
    const auto assign = [&](int64_t m, const auto& which, int32_t* out) {
        core::ParallelForRange(
            m,
            [&](int64_t begin, int64_t end) {
                std::vector<float> distance(k);
                for (int64_t i = begin; i < end; ++i) {
                    const float* x = rows + which(i) * dims;
                    std::fill(distance.begin(), distance.end(), 0.0f);
                    for (int j = 0; j < dims; ++j) {
                        const float xj = x[j];
                        const float* c = columns.data() + j * k;
                        float* d = distance.data();
                        for (int64_t p = 0; p < k; ++p) {
                            const float e = xj - c[p];
                            d[p] += e * e;
                        }
                    }
                    out[i] = int32_t(std::min_element(distance.begin(), distance.end()) -
                                     distance.begin());
                }
            },
            64);
    };
    std::vector<int32_t> sample_labels(sample_size);
    std::vector<double> sums(k * dims);
    std::vector<int64_t> counts(k);
    // Progress ("clustering"): the iterations on the sample, then the assignment of every row
    // (as long as the iterations together), in 16 reported blocks.
    constexpr double kFitShare = 0.5;
    for (int it = 0; it < kIterations; ++it) {
        core::ReportProgress("clustering", kFitShare * it / kIterations);
        assign(
            sample_size, [&](int64_t i) { return sample[i]; }, sample_labels.data());
        std::fill(sums.begin(), sums.end(), 0.0);
        std::fill(counts.begin(), counts.end(), 0);
        for (int64_t i = 0; i < sample_size; ++i) {
            const int32_t p = sample_labels[i];
            ++counts[p];
            for (int j = 0; j < dims; ++j) sums[p * dims + j] += rows[sample[i] * dims + j];
        }
        for (int64_t p = 0; p < k; ++p) {
            if (counts[p] == 0) continue;  // empty: keep the centroid
            for (int j = 0; j < dims; ++j) {
                columns[j * k + p] = static_cast<float>(sums[p * dims + j] / counts[p]);
            }
        }
    }
    constexpr int64_t kBlocks = 16;
    for (int64_t b = 0; b < kBlocks; ++b) {
        core::ReportProgress("clustering", kFitShare + (1.0 - kFitShare) * b / kBlocks);
        const int64_t begin = n * b / kBlocks, end = n * (b + 1) / kBlocks;
        assign(
            end - begin, [begin](int64_t i) { return begin + i; }, labels.data() + begin);
    }
    core::ReportProgress("clustering", 1.0);
    std::vector<float> palette(k * dims);
    for (int64_t p = 0; p < k; ++p) {
        for (int j = 0; j < dims; ++j) palette[p * dims + j] = columns[j * k + p];
    }
    return palette;
}

}  // namespace io
}  // namespace t
}  // namespace open3d
