// Test helpers for PlayCanvas SOG version 1: a v1 SOG built in memory from known splat
// values (the encoding of the v1 writers, splat-transform's write-sogs.ts of mid-2025 and
// playcanvas/sogs, rounded to the nearest code) and written with the project's own WebP
// encoder and zip writer, independently of the reader under test.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/t/io/SplatColumns.h"
#include "open3d/t/io/WebpImage.h"
#include "open3d/t/io/ZipArchive.h"

namespace open3d {
namespace t {
namespace io {
namespace sogv1 {

namespace fs = std::filesystem;
using geometry::PointCloud;
using Json = nlohmann::json;

inline const double kSqrt2 = std::sqrt(2.0);
inline int NumRest(int degree) { return (degree + 1) * (degree + 1) - 1; }
inline double LogT(double x) { return std::copysign(std::log(std::abs(x) + 1.0), x); }
inline double UnLogT(double n) { return std::copysign(std::exp(std::abs(n)) - 1.0, n); }
inline double Lerp(double lo, double hi, double t) { return lo * (1.0 - t) + hi * t; }

// A v1 SOG in memory: meta.json and its images by file name.
struct V1Sog {
    Json meta;
    std::map<std::string, Rgba8Image> images;
};

inline Rgba8Image Blank(int w, int h) {
    Rgba8Image image;
    image.width = w;
    image.height = h;
    image.rgba.assign(size_t(w) * h * 4, 0);
    return image;
}

// Writes a bundled .sog (zip) or a folder holding meta.json and the images; returns the path.
inline std::string Write(const V1Sog& sog, const std::string& path, bool zip = true) {
    std::map<std::string, std::vector<uint8_t>> entries;
    for (const auto& [name, image] : sog.images) entries[name] = EncodeWebpLossless(image);
    const std::string text = sog.meta.dump(2);
    entries["meta.json"] = std::vector<uint8_t>(text.begin(), text.end());
    if (zip) {
        ZipWriter writer;
        for (const auto& [name, bytes] : entries) writer.Add(name, bytes);
        WriteFileBytes(path, writer.Finish());
    } else {
        fs::create_directories(path);
        for (const auto& [name, bytes] : entries) WriteFileBytes(path + "/" + name, bytes);
    }
    return path;
}

inline PointCloud Read(const std::string& path) {
    PointCloud cloud;
    ReadPointCloud(path, cloud);
    return cloud;
}

// Known splats: positions, log-scales, unit quaternions, f_dc, opacity logits and an SH
// palette (each splat takes one entry, so the palette itself is exact).
struct Truth {
    int64_t n = 0;
    int degree = 0, palette = 0;
    std::vector<double> pos, log_scale, rot, dc, logit, entries;
    std::vector<int> label;
};

inline Truth RandomTruth(int64_t n, int degree, int palette, uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    Truth t;
    t.n = n;
    t.degree = degree;
    t.palette = palette;
    for (int64_t i = 0; i < n; ++i) {
        for (int a = 0; a < 3; ++a) {
            t.pos.push_back(8.0 * normal(rng));
            t.log_scale.push_back(-4.0 + 1.5 * normal(rng));
            t.dc.push_back(normal(rng));
        }
        double q[4], norm = 0;
        for (double& v : q) {
            v = normal(rng);
            norm += v * v;
        }
        for (double v : q) t.rot.push_back(v / std::sqrt(norm));
        t.logit.push_back(2.0 * normal(rng));
        t.label.push_back(palette > 0 ? int(rng() % palette) : 0);
    }
    // The highest entry: with more than 256 entries its label needs the high byte.
    if (palette > 0) t.label[n / 2] = palette - 1;
    for (int64_t k = 0; k < int64_t(palette) * NumRest(degree) * 3; ++k) {
        t.entries.push_back(0.3 * normal(rng));
    }
    return t;
}

// The v1 writers' encoding, rounded to the nearest code: value -> byte of lerp(lo, hi).
inline uint8_t Code8(double v, double lo, double hi) {
    return hi == lo ? 0 : uint8_t(std::lround(255.0 * (v - lo) / (hi - lo)));
}

inline std::pair<std::vector<double>, std::vector<double>> Ranges(const std::vector<double>& v,
                                                                  int k) {
    std::vector<double> lo(k, 1e300), hi(k, -1e300);
    for (size_t i = 0; i < v.size(); ++i) {
        lo[i % k] = std::min(lo[i % k], v[i]);
        hi[i % k] = std::max(hi[i % k], v[i]);
    }
    return {lo, hi};
}

inline V1Sog Encode(const Truth& t, int width, int height) {
    V1Sog sog;
    const int64_t n = t.n;
    for (const char* name : {"means_l.webp", "means_u.webp", "quats.webp", "scales.webp",
                             "sh0.webp", "shN_labels.webp"}) {
        sog.images[name] = Blank(width, height);
    }
    auto px = [&](const char* name, int64_t i) { return &sog.images[name].rgba[i * 4]; };
    std::vector<double> log_pos;
    for (double x : t.pos) log_pos.push_back(LogT(x));
    const auto [pmin, pmax] = Ranges(log_pos, 3);
    const auto [smin, smax] = Ranges(t.log_scale, 3);
    std::vector<double> sh0;
    for (int64_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) sh0.push_back(t.dc[i * 3 + c]);
        sh0.push_back(t.logit[i]);
    }
    const auto [cmin, cmax] = Ranges(sh0, 4);
    for (int64_t i = 0; i < n; ++i) {
        for (int a = 0; a < 3; ++a) {
            const double span = pmax[a] - pmin[a];
            const long code = std::lround(65535.0 * (log_pos[i * 3 + a] - pmin[a]) / span);
            px("means_l.webp", i)[a] = uint8_t(code & 0xff);
            px("means_u.webp", i)[a] = uint8_t(code >> 8);
            px("scales.webp", i)[a] = Code8(t.log_scale[i * 3 + a], smin[a], smax[a]);
        }
        for (int c = 0; c < 4; ++c) px("sh0.webp", i)[c] = Code8(sh0[i * 4 + c], cmin[c], cmax[c]);
        // Smallest three: the largest component (made positive) omitted, its index + 252 in A.
        const double* q = &t.rot[i * 4];
        int m = 0;
        for (int c = 1; c < 4; ++c) m = std::abs(q[c]) > std::abs(q[m]) ? c : m;
        const double sign = q[m] < 0 ? -1.0 : 1.0;
        for (int c = 0, k = 0; c < 4; ++c) {
            if (c == m) continue;
            px("quats.webp", i)[k++] = uint8_t(std::lround(255.0 * (sign * q[c] * kSqrt2 + 1) / 2));
        }
        px("quats.webp", i)[3] = uint8_t(252 + m);
        px("shN_labels.webp", i)[0] = uint8_t(t.label[i] & 0xff);
        px("shN_labels.webp", i)[1] = uint8_t(t.label[i] >> 8);
    }
    // Trailing texels are padding: garbage there must not matter.
    for (int64_t i = n; i < int64_t(width) * height; ++i) {
        px("quats.webp", i)[3] = 7;
        px("shN_labels.webp", i)[0] = px("shN_labels.webp", i)[1] = 0xff;
    }
    sog.meta["means"] = {{"shape", Json::array({n, 3})},
                         {"dtype", "float32"},
                         {"mins", pmin},
                         {"maxs", pmax},
                         {"files", Json::array({"means_l.webp", "means_u.webp"})}};
    sog.meta["scales"] = {{"shape", Json::array({n, 3})},
                          {"mins", smin},
                          {"maxs", smax},
                          {"files", Json::array({"scales.webp"})}};
    sog.meta["quats"] = {{"shape", Json::array({n, 4})},
                         {"encoding", "quaternion_packed"},
                         {"files", Json::array({"quats.webp"})}};
    sog.meta["sh0"] = {{"shape", Json::array({n, 1, 4})},
                       {"mins", cmin},
                       {"maxs", cmax},
                       {"files", Json::array({"sh0.webp"})}};
    if (t.degree == 0) {
        sog.images.erase("shN_labels.webp");
        return sog;
    }
    const int nc = NumRest(t.degree);
    const auto [emin, emax] = Ranges(t.entries, 1);
    Rgba8Image centroids = Blank(64 * nc, (t.palette + 63) / 64);
    for (int e = 0; e < t.palette; ++e) {
        for (int j = 0; j < nc; ++j) {
            uint8_t* texel = &centroids.rgba[((e / 64) * centroids.width + (e % 64) * nc + j) * 4];
            for (int c = 0; c < 3; ++c) {
                texel[c] = Code8(t.entries[(e * nc + j) * 3 + c], emin[0], emax[0]);
            }
        }
    }
    sog.images["shN_centroids.webp"] = centroids;
    sog.meta["shN"] = {{"shape", Json::array({n, nc})},
                       {"mins", emin[0]},
                       {"maxs", emax[0]},
                       {"quantization", 8},
                       {"files", Json::array({"shN_centroids.webp", "shN_labels.webp"})}};
    return sog;
}

// Reading `path` fails with an error naming it and containing every one of `parts`.
inline void ExpectError(const std::string& path, const std::vector<std::string>& parts) {
    PointCloud cloud;
    try {
        ReadPointCloud(path, cloud);
        ADD_FAILURE() << path << " was read";
    } catch (const core::Open3DError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(path), std::string::npos) << message;
        for (const std::string& part : parts) {
            EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' in: " << message;
        }
    }
}

}  // namespace sogv1
}  // namespace io
}  // namespace t
}  // namespace open3d
