// antimatter15 .splat: 32 bytes per splat, little endian: position float32 x3, linear
// scale float32 x3, colour RGBA uint8 (alpha = sigmoid(opacity)), rotation uint8 x4
// (w, x, y, z) as q * 128 + 128 clamped to 0..255. No SH beyond degree 0.

#include <algorithm>
#include <cmath>
#include <cstring>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/SplatColumns.h"

namespace open3d {
namespace t {
namespace io {
namespace {

constexpr int64_t kSplatBytes = 32;
// alpha 0 and 255 would be logits of -inf/+inf; this margin keeps them finite and still
// re-encodes to the same byte (1e-6 * 255 rounds to 0).
constexpr double kAlphaMargin = 1e-6;

uint8_t QuantiseUnit(double v) {  // v in [0, 1] -> 0..255, rounded
    return static_cast<uint8_t>(std::clamp(std::lround(v * 255.0), 0L, 255L));
}

}  // namespace

geometry::PointCloud ReadSplat(const std::string& filename, const ReadPointCloudOptions& options,
                               ReadPointCloudReport& report) {
    const MappedFile bytes(filename);
    const int64_t size = static_cast<int64_t>(bytes.size());
    if (LooksLikeKsplat(bytes.data(), bytes.size())) {
        core::ThrowError(
            "'{}': this is a .ksplat file (GaussianSplats3D, version 0.{}) named .splat; "
            "rename it to .ksplat to read it",
            filename, int(bytes.data()[1]));
    }
    if (size % kSplatBytes != 0) {
        core::ThrowError(
            "'{}': size {} bytes is not a multiple of 32 (.splat record size): the "
            "file is truncated (splat {} is incomplete)",
            filename, size, size / kSplatBytes);
    }
    const int64_t n = size / kSplatBytes;
    SplatColumns columns;
    columns.Allocate(filename, n, /*gaussian=*/true, /*degree=*/0);
    float* positions = columns.positions.Data<float>();
    float* scale = columns.scale.Data<float>();
    float* f_dc = columns.f_dc.Data<float>();
    float* opacity = columns.opacity.Data<float>();
    float* rot = columns.rot.Data<float>();
    core::ParallelFor(
        n,
        [&](int64_t i) {
            const uint8_t* record = bytes.data() + i * kSplatBytes;
            float floats[6];
            std::memcpy(floats, record, sizeof(floats));
            for (int c = 0; c < 3; ++c) {
                positions[i * 3 + c] = floats[c];
                scale[i * 3 + c] = floats[3 + c];
            }
            const uint8_t* rgba = record + 24;
            for (int c = 0; c < 3; ++c) {
                f_dc[i * 3 + c] = static_cast<float>((rgba[c] / 255.0 - 0.5) / geometry::kSH_C0);
            }
            const double alpha = std::clamp(rgba[3] / 255.0, kAlphaMargin, 1.0 - kAlphaMargin);
            opacity[i] = static_cast<float>(std::log(alpha / (1.0 - alpha)));
            for (int c = 0; c < 4; ++c) {
                rot[i * 4 + c] = static_cast<float>((record[28 + c] - 128) / 128.0);
            }
        },
        4096);
    // .splat stores linear scales: a negative one is no Gaussian (the log other formats
    // store cannot even hold it), so the file is damaged or not a .splat at all.
    for (int64_t i = 0; i < n * 3; ++i) {
        if (scale[i] < 0.0f) {
            core::ThrowError(
                "'{}': splat {} has a negative scale {} (axis {}); .splat stores linear scales, "
                "which must be >= 0",
                filename, i / 3, scale[i], i % 3);
        }
    }
    return FinalizeColumns(filename, columns, options, report);
}

void WriteSplat(const std::string& filename, const geometry::PointCloud& cloud) {
    if (!cloud.IsGaussianSplat()) {
        core::ThrowError(
            "Cannot write '{}': .splat needs a Gaussian splat cloud (scale, rot, "
            "opacity, f_dc)",
            filename);
    }
    const geometry::GaussianSplatArrays a = cloud.GetGaussianSplatArrays();
    if (a.sh_degree > 0) {
        core::LogWarning("'{}': .splat holds SH degree 0 only; f_rest (degree {}) is not written",
                         filename, a.sh_degree);
    }
    const int64_t n = a.num_points;
    const float *positions = a.positions, *scale = a.scale, *rot = a.rot;
    const float *opacity = a.opacity, *f_dc = a.f_dc;
    std::vector<uint8_t> bytes(n * kSplatBytes);
    std::vector<uint8_t> clamped(n, 0);
    core::ParallelFor(
        n,
        [&](int64_t i) {
            uint8_t* record = bytes.data() + i * kSplatBytes;
            std::memcpy(record, positions + i * 3, 12);
            std::memcpy(record + 12, scale + i * 3, 12);
            for (int c = 0; c < 3; ++c) {
                const double colour = 0.5 + geometry::kSH_C0 * f_dc[i * 3 + c];
                if (colour < -0.5 / 255 || colour > 1.0 + 0.5 / 255) clamped[i] = 1;
                record[24 + c] = QuantiseUnit(colour);
            }
            record[27] = QuantiseUnit(1.0 / (1.0 + std::exp(-double(opacity[i]))));
            const float* q = rot + i * 4;
            const double norm = std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] +
                                          double(q[2]) * q[2] + double(q[3]) * q[3]);
            for (int c = 0; c < 4; ++c) {
                const double v = norm > 0 ? q[c] / norm : 0.0;
                record[28 + c] =
                    static_cast<uint8_t>(std::clamp(std::lround(v * 128.0 + 128.0), 0L, 255L));
            }
        },
        4096);
    const int64_t num_clamped = std::count(clamped.begin(), clamped.end(), 1);
    if (num_clamped > 0) {
        core::LogWarning(
            "'{}': {} splats have base colours outside [0, 1], clamped by .splat's "
            "8-bit colour",
            filename, num_clamped);
    }
    WriteFileBytes(filename, bytes);
}

}  // namespace io
}  // namespace t
}  // namespace open3d
