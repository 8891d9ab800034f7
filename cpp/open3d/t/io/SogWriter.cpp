// The SOG writer (layout and choices: SogLayout.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/core/Progress.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/Codebook.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/SogLayout.h"
#include "open3d/t/io/SplatColumns.h"
#include "open3d/t/io/WebpImage.h"
#include "open3d/t/io/ZipArchive.h"

namespace open3d {
namespace t {
namespace io {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace sog;

// Smallest-three bytes of a unit quaternion (w, x, y, z) in the mode that decodes closest
// to it (the largest component, or a near tie that reproduces it better) among the modes that
// decode to a unit quaternion.
void EncodeQuat(const double q[4], uint8_t out[4]) {
    int largest = 0;
    for (int c = 1; c < 4; ++c) {
        if (std::abs(q[c]) > std::abs(q[largest])) largest = c;
    }
    double best = std::numeric_limits<double>::max();
    for (int mode = 0; mode < 4; ++mode) {
        const double sign = q[mode] < 0 ? -1.0 : 1.0;
        uint8_t t[4];
        for (int c = 0, k = 0; c < 4; ++c) {
            if (c == mode) continue;
            const double v = sign * q[c] * kSqrt2 * 0.5 + 0.5;
            t[k++] = static_cast<uint8_t>(std::clamp(std::lround(v * 255.0), 0L, 255L));
        }
        t[3] = static_cast<uint8_t>(252 + mode);
        // Only modes whose three stored components leave room for the fourth (a^2 + b^2 + c^2
        // <= 1) decode to a unit quaternion, which reads back and re-encodes to these bytes.
        double stored = 0;
        for (int k = 0; k < 3; ++k) {
            const double v = (t[k] / 255.0 * 2.0 - 1.0) / kSqrt2;
            stored += v * v;
        }
        if (stored > 1.0 && mode != largest) continue;
        double d[4];
        DecodeQuat(t, mode, d);
        const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + d[3] * d[3]);
        const double dot = std::abs(d[0] * q[0] + d[1] * q[1] + d[2] * q[2] + d[3] * q[3]) / norm;
        const double error = 1.0 - dot;
        if (error < best) {
            best = error;
            std::copy_n(t, 4, out);
        }
    }
}

Json FloatArray(const std::vector<float>& v) {
    Json a = Json::array();
    for (float f : v) a.push_back(double(f));
    return a;
}

}  // namespace

void WriteSog(const std::string& filename, const geometry::PointCloud& cloud) {
    if (!cloud.IsGaussianSplat()) {
        core::ThrowError(
            "Cannot write '{}': SOG needs a Gaussian splat cloud (scale, rot, opacity, f_dc)",
            filename);
    }
    const geometry::GaussianSplatArrays a = cloud.GetGaussianSplatArrays();
    const int64_t n = a.num_points;
    if (n > kMaxTexels) {
        core::ThrowError("Cannot write '{}': {} splats, more than the {} a SOG written here holds",
                         filename, n, kMaxTexels);
    }
    for (int64_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            if (!std::isfinite(a.positions[i * 3 + c])) {
                core::ThrowError("Cannot write '{}': splat {} has a non-finite position", filename,
                                 i);
            }
        }
    }
    // Texture size as PlayCanvas writes it: a near-square, both sides multiples of 4.
    const int width = std::max(4, int(std::ceil(std::sqrt(double(n)) / 4.0)) * 4);
    const int height = std::max(4, int(std::ceil(double(n) / width / 4.0)) * 4);
    const size_t texels = size_t(width) * height;
    auto plane = [&] {
        Rgba8Image image;
        image.width = width;
        image.height = height;
        image.rgba.insert(image.rgba.end(), texels * 4, uint8_t(0));
        return image;
    };

    // Positions: 16-bit codes of the log transform between its per-axis min and max.
    double mins[3], maxs[3];
    for (int c = 0; c < 3; ++c) {
        mins[c] = n > 0 ? std::numeric_limits<double>::max() : 0.0;
        maxs[c] = n > 0 ? std::numeric_limits<double>::lowest() : 0.0;
    }
    for (int64_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            const double l = LogTransform(a.positions[i * 3 + c]);
            mins[c] = std::min(mins[c], l);
            maxs[c] = std::max(maxs[c], l);
        }
    }
    Rgba8Image means_l = plane(), means_u = plane(), quats = plane(), scales = plane(),
               sh0 = plane();
    core::ParallelFor(n, [&](int64_t i) {
        for (int c = 0; c < 3; ++c) {
            const double range = maxs[c] - mins[c];
            const double t =
                range > 0 ? (LogTransform(a.positions[i * 3 + c]) - mins[c]) / range : 0.0;
            const long q = std::clamp(std::lround(t * 65535.0), 0L, 65535L);
            means_l.rgba[i * 4 + c] = uint8_t(q & 0xff);
            means_u.rgba[i * 4 + c] = uint8_t(q >> 8);
        }
        means_l.rgba[i * 4 + 3] = 255;
        means_u.rgba[i * 4 + 3] = 255;
    });

    std::vector<uint8_t> zero_quat(n, 0);
    core::ParallelFor(n, [&](int64_t i) {
        const float* r = a.rot + i * 4;
        double q[4];
        double norm = 0;
        for (int c = 0; c < 4; ++c) norm += double(r[c]) * r[c];
        norm = std::sqrt(norm);
        if (!(norm > 0) || !std::isfinite(norm)) {
            zero_quat[i] = 1;
            return;
        }
        for (int c = 0; c < 4; ++c) q[c] = r[c] / norm;
        EncodeQuat(q, &quats.rgba[i * 4]);
    });
    if (const auto it = std::find(zero_quat.begin(), zero_quat.end(), 1); it != zero_quat.end()) {
        core::ThrowError("Cannot write '{}': splat {} has a zero or non-finite rotation quaternion",
                         filename, it - zero_quat.begin());
    }

    // Scales (as natural logs, like the PLY) and DC colours: one 256-entry codebook each.
    std::vector<float> log_scales(n * 3), dc(n * 3);
    core::ParallelFor(n * 3, [&](int64_t k) {
        log_scales[k] = EncodeLogScale(a.scale[k]);
        dc[k] = a.f_dc[k];
    });
    for (const auto* column : {&log_scales, &dc}) {
        for (int64_t k = 0; k < n * 3; ++k) {
            if (!std::isfinite((*column)[k])) {
                core::ThrowError("Cannot write '{}': splat {} has a non-finite {}", filename, k / 3,
                                 column == &dc ? "f_dc" : "scale");
            }
        }
    }
    std::vector<uint8_t> scale_labels, dc_labels;
    // The scale codebook weighs each log-scale by its splat's linear size relative to the
    // largest (floored at 1/100): a plain k-means spends its entries where splats are many,
    // the small ones, and rounds the few large splats down by up to half, which shows; tiny
    // splats stay tiny at any rounding. docs/formats.md has the round trips before and after.
    const float top_log_scale = *std::max_element(log_scales.begin(), log_scales.end());
    std::vector<float> scale_weights(log_scales.size());
    core::ParallelFor(int64_t(log_scales.size()), [&](int64_t k) {
        scale_weights[k] = static_cast<float>(
            std::max(std::exp(double(log_scales[k]) - double(top_log_scale)), 1e-2));
    });
    const std::vector<float> scale_codebook = Quantise1D(log_scales, scale_labels, scale_weights);
    const std::vector<float> dc_codebook = Quantise1D(dc, dc_labels);
    core::ParallelFor(n, [&](int64_t i) {
        for (int c = 0; c < 3; ++c) {
            scales.rgba[i * 4 + c] = scale_labels[i * 3 + c];
            sh0.rgba[i * 4 + c] = dc_labels[i * 3 + c];
        }
        scales.rgba[i * 4 + 3] = 255;
        const double alpha = 1.0 / (1.0 + std::exp(-double(a.opacity[i])));
        sh0.rgba[i * 4 + 3] =
            static_cast<uint8_t>(std::clamp(std::lround(alpha * 255.0), 0L, 255L));
    });

    std::vector<std::pair<std::string, Rgba8Image>> images;
    images.emplace_back("means_l.webp", std::move(means_l));
    images.emplace_back("means_u.webp", std::move(means_u));
    images.emplace_back("scales.webp", std::move(scales));
    images.emplace_back("quats.webp", std::move(quats));
    images.emplace_back("sh0.webp", std::move(sh0));

    Json meta = Json::object();
    meta["version"] = kWriteVersion;
    meta["asset"] = {{"generator", "open3d t/io SogFormat"}};
    meta["count"] = n;
    meta["antialias"] = false;
    meta["means"] = {{"mins", Json::array({mins[0], mins[1], mins[2]})},
                     {"maxs", Json::array({maxs[0], maxs[1], maxs[2]})},
                     {"files", Json::array({"means_l.webp", "means_u.webp"})}};
    meta["scales"] = {{"codebook", FloatArray(scale_codebook)},
                      {"files", Json::array({"scales.webp"})}};
    meta["quats"] = {{"files", Json::array({"quats.webp"})}};
    meta["sh0"] = {{"codebook", FloatArray(dc_codebook)}, {"files", Json::array({"sh0.webp"})}};

    if (a.sh_degree > 0 && n > 0) {
        const int nc = a.num_rest;
        const int dims = nc * 3;
        for (int64_t k = 0; k < n * dims; ++k) {
            if (!std::isfinite(a.f_rest[k])) {
                core::ThrowError("Cannot write '{}': splat {} has a non-finite f_rest", filename,
                                 k / dims);
            }
        }
        std::vector<int32_t> labels;
        const std::vector<float> palette = Palette(a.f_rest, n, dims, labels);
        const int64_t entries = int64_t(palette.size()) / dims;
        std::vector<uint8_t> coefficient_labels;
        const std::vector<float> codebook = Quantise1D(palette, coefficient_labels);
        Rgba8Image centroids;
        centroids.width = 64 * nc;
        centroids.height = int((entries + 63) / 64);
        centroids.rgba.insert(centroids.rgba.end(), size_t(centroids.width) * centroids.height * 4,
                              uint8_t(0));
        for (int64_t p = 0; p < entries; ++p) {
            uint8_t* row = centroids.rgba.data() + ((p / 64) * centroids.width + (p % 64) * nc) * 4;
            for (int j = 0; j < nc; ++j) {
                for (int c = 0; c < 3; ++c)
                    row[j * 4 + c] = coefficient_labels[p * dims + j * 3 + c];
                row[j * 4 + 3] = 255;
            }
        }
        Rgba8Image label_image = plane();
        for (int64_t i = 0; i < n; ++i) {
            label_image.rgba[i * 4 + 0] = uint8_t(labels[i] & 0xff);
            label_image.rgba[i * 4 + 1] = uint8_t(labels[i] >> 8);
            label_image.rgba[i * 4 + 3] = 255;
        }
        images.emplace_back("shN_centroids.webp", std::move(centroids));
        images.emplace_back("shN_labels.webp", std::move(label_image));
        meta["shN"] = {{"count", entries},
                       {"bands", a.sh_degree},
                       {"codebook", FloatArray(codebook)},
                       {"files", Json::array({"shN_centroids.webp", "shN_labels.webp"})}};
    }

    // Lossless WebP, images in parallel; in pairs with a progress report after each when
    // someone watches (the last step of a large scene takes seconds).
    std::vector<std::vector<uint8_t>> encoded(images.size());
    const int64_t wave = core::HasProgressCallback() ? 2 : int64_t(images.size());
    for (int64_t first = 0; first < int64_t(images.size()); first += wave) {
        core::ReportProgress("compressing", double(first) / images.size());
        const int64_t count = std::min<int64_t>(wave, int64_t(images.size()) - first);
        core::ParallelFor(
            count,
            [&](int64_t k) { encoded[first + k] = EncodeWebpLossless(images[first + k].second); },
            1);
    }
    core::ReportProgress("compressing", 1.0);
    ZipWriter zip;
    for (size_t k = 0; k < images.size(); ++k) zip.Add(images[k].first, encoded[k]);
    const std::string text = meta.dump();
    zip.Add("meta.json", std::vector<uint8_t>(text.begin(), text.end()));
    WriteFileBytes(filename, zip.Finish());
}

}  // namespace io
}  // namespace t
}  // namespace open3d
