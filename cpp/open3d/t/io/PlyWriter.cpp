// 3DGS PLY writer: x y z nx ny nz f_dc_* f_rest_* opacity scale_* (natural log) rot_*.

#include <cmath>
#include <cstring>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/SplatColumns.h"

namespace open3d {
namespace t {
namespace io {

float EncodeLogScale(float scale) {
    if (scale == 0.0f) return -1000.0f;  // exp(-1000) is 0 in double, so the reader gets 0 back
    const float nearest = static_cast<float>(std::log(static_cast<double>(scale)));
    if (!std::isfinite(nearest) || DecodeLogScale(nearest) == scale) return nearest;
    // Near log = 0, several floats map to one scale; far from it one ulp of the log jumps
    // several ulps of the scale. A few steps either way find the exact preimage when it exists.
    float down = nearest, up = nearest;
    for (int step = 0; step < 8; ++step) {
        down = std::nextafter(down, -INFINITY);
        up = std::nextafter(up, INFINITY);
        if (DecodeLogScale(down) == scale) return down;
        if (DecodeLogScale(up) == scale) return up;
    }
    return nearest;
}

namespace {

std::vector<std::string> PropertyNames(bool gaussian, int num_rest) {
    std::vector<std::string> names = {"x", "y", "z"};
    if (!gaussian) return names;
    for (const char* n : {"nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"}) names.push_back(n);
    for (int k = 0; k < num_rest; ++k) names.push_back("f_rest_" + std::to_string(k));
    for (const char* n :
         {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"}) {
        names.push_back(n);
    }
    return names;
}

// Fills row i with the file's values in PropertyNames order (`a` is null for a plain cloud).
void FillRow(const float* positions, const geometry::GaussianSplatArrays* a, int64_t i,
             float* row) {
    for (int c = 0; c < 3; ++c) *row++ = positions[i * 3 + c];
    if (a == nullptr) return;
    for (int c = 0; c < 3; ++c) *row++ = 0.0f;  // normals: unused by 3DGS, kept for the layout
    for (int c = 0; c < 3; ++c) *row++ = a->f_dc[i * 3 + c];
    const int nc = a->num_rest;
    if (nc > 0) {
        const float* rest = a->f_rest + i * nc * 3;
        for (int c = 0; c < 3; ++c) {
            for (int k = 0; k < nc; ++k) *row++ = rest[k * 3 + c];  // channel-major in the file
        }
    }
    *row++ = a->opacity[i];
    for (int c = 0; c < 3; ++c) *row++ = EncodeLogScale(a->scale[i * 3 + c]);
    for (int c = 0; c < 4; ++c) *row++ = a->rot[i * 4 + c];
}

}  // namespace

void WritePly(const std::string& filename, const geometry::PointCloud& cloud, PlyFormat format) {
    if (!cloud.HasPointAttr(geometry::gs_attr::kPositions)) {
        core::ThrowError("Cannot write '{}': the point cloud has no positions", filename);
    }
    const bool gaussian = cloud.IsGaussianSplat();
    geometry::GaussianSplatArrays arrays;
    if (gaussian) arrays = cloud.GetGaussianSplatArrays();
    const int nc = arrays.num_rest;
    if (gaussian) {
        const float* s = arrays.scale;
        for (int64_t k = 0; k < cloud.NumPoints() * 3; ++k) {
            if (s[k] < 0.0f) {
                core::ThrowError("Cannot write '{}': splat {} has a negative scale {}", filename,
                                 k / 3, s[k]);
            }
        }
    }
    std::vector<std::string> skipped;
    for (const auto& name : cloud.GetPointAttrNames()) {
        const bool written = name == geometry::gs_attr::kPositions ||
                             (gaussian && (name == "scale" || name == "rot" || name == "opacity" ||
                                           name == "f_dc" || name == "f_rest"));
        if (!written) skipped.push_back(name);
    }
    if (!skipped.empty()) {
        core::LogWarning("'{}': attributes not written by the 3DGS PLY layout: {}", filename,
                         fmt::join(skipped, ", "));
    }

    const std::vector<std::string> names = PropertyNames(gaussian, nc * 3);
    const int64_t n = cloud.NumPoints();
    const int64_t width = static_cast<int64_t>(names.size());
    std::string header = "ply\nformat ";
    header += format == PlyFormat::Ascii             ? "ascii"
              : format == PlyFormat::BinaryBigEndian ? "binary_big_endian"
                                                     : "binary_little_endian";
    header += " 1.0\ncomment written by open3d (3DGS layout: log-scales, opacity logits)\n";
    header += fmt::format("element vertex {}\n", n);
    for (const auto& name : names) header += "property float " + name + "\n";
    header += "end_header\n";

    const float* positions = cloud.GetPointPositions().Data<float>();  // [N, 3]
    std::vector<float> values(n * width);
    core::ParallelFor(
        n,
        [&](int64_t i) { FillRow(positions, gaussian ? &arrays : nullptr, i, &values[i * width]); },
        4096);

    std::vector<uint8_t> bytes(header.begin(), header.end());
    if (format == PlyFormat::Ascii) {
        fmt::memory_buffer text;
        for (int64_t i = 0; i < n; ++i) {
            // "{}" prints the shortest text that parses back to the same float.
            fmt::format_to(
                std::back_inserter(text), "{}\n",
                fmt::join(values.begin() + i * width, values.begin() + (i + 1) * width, " "));
        }
        bytes.insert(bytes.end(), text.begin(), text.end());
    } else {
        const size_t start = bytes.size();
        const auto* raw = reinterpret_cast<const uint8_t*>(values.data());
        bytes.insert(bytes.end(), raw, raw + values.size() * sizeof(float));
        if (format == PlyFormat::BinaryBigEndian) {
            for (size_t k = start; k < bytes.size(); k += 4) std::reverse(&bytes[k], &bytes[k] + 4);
        }
    }
    WriteFileBytes(filename, bytes);
}

}  // namespace io
}  // namespace t
}  // namespace open3d
