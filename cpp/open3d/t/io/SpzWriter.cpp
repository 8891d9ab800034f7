// The SPZ v4 writer (layout and choices: SpzLayout.h).
#include <zstd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/io/ByteCodecs.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/SplatColumns.h"
#include "open3d/t/io/SpzLayout.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using namespace spz;

uint8_t ToByte(double v) { return uint8_t(std::clamp(std::round(v), 0.0, 255.0)); }

/// The largest fractionalBits <= 12 whose 24-bit range holds every coordinate:
/// max|p| * 2^bits <= 2^23 - 1, so rounding cannot leave the range. A cloud read back from
/// the file gets the same choice, which keeps write -> read -> write byte-identical.
int ChooseFractionalBits(const std::string& filename, const float* positions, int64_t n) {
    double max_abs = 0;
    for (int64_t i = 0; i < n * 3; ++i) max_abs = std::max(max_abs, double(std::abs(positions[i])));
    for (int bits = kWriteFractionalBits; bits >= 0; --bits) {
        if (max_abs * std::ldexp(1.0, bits) <= kMaxFixed) return bits;
    }
    core::ThrowError(
        "Cannot write '{}': a coordinate of magnitude {} exceeds SPZ's 24-bit "
        "position range (+-{} with 0 fractional bits)",
        filename, max_abs, kMaxFixed);
}

/// c * 128 + 128 rounded to the nearest multiple of `bucket` (the SPZ writers' reduced
/// precision, which zstd then stores compactly). The reference rounds to an integer first
/// and then to the bucket; one rounding halves the worst case (4.5/128 -> 4/128 at 5 bits).
uint8_t QuantiseSH(double v, int bucket) {
    const double q = std::round(std::clamp(v * 128.0 + 128.0, 0.0, 256.0) / bucket) * bucket;
    return uint8_t(std::min(q, 255.0));
}

/// q (x, y, z, w, unit) with component `largest` left out (made positive).
uint32_t PackSmallestThreeWithout(const double q[4], int largest) {
    const bool negate = q[largest] < 0;  // q and -q are the same rotation
    uint32_t packed = uint32_t(largest);
    for (int k = 0; k < 4; ++k) {
        if (k == largest) continue;
        // signbit: encoders store the sign of components that round to magnitude 0, which
        // the reader keeps as -0.0; this writes them back as they were.
        const uint32_t sign = std::signbit(q[k]) != negate ? 1 : 0;
        const uint32_t magnitude =
            std::min(511u, uint32_t(std::abs(q[k]) / kSqrtHalf * 511.0 + 0.5));
        packed = packed << 10 | sign << 9 | magnitude;
    }
    return packed;
}

/// Smallest-three encoding of a (w, x, y, z) rotation given in RDF. The component left
/// out is the largest, as in the reference; where another one is within a quantisation
/// step of it, the candidate that decodes closest to q wins. That keeps a rotation read
/// from SPZ on its original encoding (the stored components come back exactly, the derived
/// one need not stay the largest), so write -> read -> write gives the same bytes.
uint32_t PackSmallestThree(const float* rot_wxyz, const AxisFlips& flips) {
    const double norm =
        std::sqrt(double(rot_wxyz[0]) * rot_wxyz[0] + double(rot_wxyz[1]) * rot_wxyz[1] +
                  double(rot_wxyz[2]) * rot_wxyz[2] + double(rot_wxyz[3]) * rot_wxyz[3]);
    double q[4];  // x, y, z, w in the stored axes
    for (int k = 0; k < 3; ++k) q[k] = rot_wxyz[1 + k] / norm * flips.quaternion_xyz[k];
    q[3] = rot_wxyz[0] / norm;
    double max_abs = 0;
    for (double v : q) max_abs = std::max(max_abs, std::abs(v));
    uint32_t best = 0;
    double best_error = std::numeric_limits<double>::infinity(), best_abs = 0;
    for (int largest = 0; largest < 4; ++largest) {
        const double abs_largest = std::abs(q[largest]);
        if (abs_largest < max_abs - kSqrtHalf / 511) continue;
        const uint32_t packed = PackSmallestThreeWithout(q, largest);
        double back[4], error = 0;
        UnpackSmallestThree(packed, back);
        const double sign = q[largest] < 0 ? -1 : 1;
        for (int k = 0; k < 4; ++k) error += (back[k] - sign * q[k]) * (back[k] - sign * q[k]);
        if (error < best_error || (error == best_error && abs_largest > best_abs)) {
            best = packed;
            best_error = error;
            best_abs = abs_largest;
        }
    }
    return best;
}

enum WriteStatus : uint8_t {
    kNonFinite = 1,
    kZeroRotation = 2,
    kNegativeScale = 4,
    kColourClamped = 8,  // the three clamp bits are consecutive
    kScaleClamped = 16,
    kSHClamped = 32,
};

/// One splat's attributes as (name, pointer, width) rows, for the finiteness check.
struct SplatValues {
    const char* names[6];
    const float* data[6];
    int width[6];
};
SplatValues SplatValuesOf(const geometry::GaussianSplatArrays& a, int64_t i) {
    const int nc = a.num_rest;
    return {{"position", "scale", "rot", "opacity", "f_dc", "f_rest"},
            {a.positions + i * 3, a.scale + i * 3, a.rot + i * 4, a.opacity + i, a.f_dc + i * 3,
             nc > 0 ? a.f_rest + i * nc * 3 : nullptr},
            {3, 3, 4, 1, 3, nc * 3}};
}

/// The six attribute arrays of a valid splat cloud, quantised and in RUB. Throws naming
/// the first splat SPZ cannot hold; warns once about values its 8-bit ranges clamp.
Streams EncodeStreams(const std::string& filename, const geometry::GaussianSplatArrays& a,
                      const Header& h) {
    const int64_t n = a.num_points;
    const int nc = a.num_rest;
    const AxisFlips flips = FlipsToRDF(kCoordinateRUB);  // RDF -> RUB is the same map
    Streams raw;
    for (int k = 0; k < kNumStreams; ++k) raw[k].resize(h.StreamBytes(k));
    std::vector<uint8_t> status(n, 0);  // WriteStatus bits per splat
    const double position_scale = std::ldexp(1.0, h.fractional_bits);
    core::ParallelFor(
        n,
        [&](int64_t i) {
            const SplatValues values = SplatValuesOf(a, i);
            for (int c = 0; c < 6; ++c) {
                for (int k = 0; k < values.width[c]; ++k) {
                    if (!std::isfinite(values.data[c][k])) status[i] |= kNonFinite;
                }
            }
            const float* q = a.rot + i * 4;
            if (q[0] == 0 && q[1] == 0 && q[2] == 0 && q[3] == 0) status[i] |= kZeroRotation;
            for (int k = 0; k < 3; ++k) {
                if (a.scale[i * 3 + k] < 0) status[i] |= kNegativeScale;
            }
            if (status[i] != 0) return;
            for (int k = 0; k < 3; ++k) {
                const int32_t fixed = int32_t(std::round(double(a.positions[i * 3 + k]) *
                                                         flips.position[k] * position_scale));
                uint8_t* p = raw[kPositions].data() + i * 9 + k * 3;
                for (int b = 0; b < 3; ++b) p[b] = uint8_t(uint32_t(fixed) >> (8 * b));
                const double colour = a.f_dc[i * 3 + k] * (kColourScale * 255.0) + 127.5;
                if (colour < -0.5 || colour > 255.5) status[i] |= kColourClamped;
                raw[kColours][i * 3 + k] = ToByte(colour);
                const float s = a.scale[i * 3 + k];  // zero: the smallest step
                const double log_scale = s > 0 ? (std::log(double(s)) + 10.0) * 16.0 : -1.0;
                if (log_scale < -0.5 || log_scale > 255.5) status[i] |= kScaleClamped;
                raw[kScales][i * 3 + k] = ToByte(log_scale);
            }
            raw[kAlphas][i] = ToByte(255.0 / (1.0 + std::exp(-double(a.opacity[i]))));
            StoreU32(raw[kRotations].data() + i * 4, PackSmallestThree(q, flips));
            if (nc == 0) return;
            const float* rest = a.f_rest + i * nc * 3;
            uint8_t* sh = raw[kSH].data() + i * nc * 3;
            for (int k = 0; k < nc; ++k) {
                for (int ch = 0; ch < 3; ++ch) {
                    const double v = double(rest[k * 3 + ch]) * flips.sh[k];
                    if (v < -1.0 || v > 127.0 / 128.0) status[i] |= kSHClamped;
                    sh[k * 3 + ch] = QuantiseSH(v, k < 3 ? kSH1Bucket : kSHRestBucket);
                }
            }
        },
        4096);
    int64_t clamped[3] = {0, 0, 0};  // colour, scale, SH
    for (int64_t i = 0; i < n; ++i) {
        if (status[i] & kNonFinite) {
            const SplatValues values = SplatValuesOf(a, i);
            for (int c = 0; c < 6; ++c) {
                for (int k = 0; k < values.width[c]; ++k) {
                    if (std::isfinite(values.data[c][k])) continue;
                    core::ThrowError("Cannot write '{}': splat {} has a non-finite {}[{}] = {}",
                                     filename, i, values.names[c], k, values.data[c][k]);
                }
            }
        }
        if (status[i] & kZeroRotation) {
            core::ThrowError("Cannot write '{}': splat {} has a zero rotation quaternion", filename,
                             i);
        }
        if (status[i] & kNegativeScale) {
            core::ThrowError("Cannot write '{}': splat {} has a negative scale", filename, i);
        }
        for (int b = 0; b < 3; ++b) clamped[b] += (status[i] & (kColourClamped << b)) ? 1 : 0;
    }
    if (clamped[0] + clamped[1] + clamped[2] > 0) {
        core::LogWarning(
            "'{}': SPZ's 8-bit range clamped the base colour of {} splats, the scale "
            "of {} (log-scale outside [-10, 5.97]) and the SH of {} (outside [-1, "
            "0.99])",
            filename, clamped[0], clamped[1], clamped[2]);
    }

    return raw;
}

/// A v4 file: header, TOC, one zstd frame per non-empty stream.
std::vector<uint8_t> AssembleV4(const Header& h, const Streams& raw) {
    std::array<int, kNumStreams> present{};
    const int num_streams = h.PresentStreams(present);
    std::array<std::vector<uint8_t>, kNumStreams> compressed;
    core::ParallelFor(
        num_streams,
        [&](int64_t s) {
            const std::vector<uint8_t>& in = raw[present[s]];
            compressed[s] = ZstdCompressBytes(in.data(), in.size());
        },
        1);
    std::vector<uint8_t> bytes(kHeaderBytes + num_streams * 16, 0);
    StoreU32(bytes.data(), kMagic);
    StoreU32(bytes.data() + 4, h.version);
    StoreU32(bytes.data() + 8, h.num_points);
    bytes[12] = uint8_t(h.sh_degree);
    bytes[13] = uint8_t(h.fractional_bits);
    bytes[14] = 0;  // flags: the cloud carries no antialiasing mark and no extensions
    bytes[15] = uint8_t(num_streams);
    StoreU32(bytes.data() + 16, uint32_t(kHeaderBytes));
    for (int s = 0; s < num_streams; ++s) {
        StoreU64(bytes.data() + kHeaderBytes + s * 16, compressed[s].size());
        StoreU64(bytes.data() + kHeaderBytes + s * 16 + 8, raw[present[s]].size());
    }
    for (int s = 0; s < num_streams; ++s) {
        bytes.insert(bytes.end(), compressed[s].begin(), compressed[s].end());
    }
    return bytes;
}

}  // namespace

void WriteSpz(const std::string& filename, const geometry::PointCloud& cloud) {
    if (!cloud.IsGaussianSplat()) {
        core::ThrowError(
            "Cannot write '{}': SPZ needs a Gaussian splat cloud (scale, rot, "
            "opacity, f_dc)",
            filename);
    }
    const geometry::GaussianSplatArrays a = cloud.GetGaussianSplatArrays();
    const int64_t n = a.num_points;
    if (n == 0 || n > std::numeric_limits<int32_t>::max()) {
        core::ThrowError(
            "Cannot write '{}': SPZ holds 1 to 2^31-1 splats (the reference loader "
            "refuses 0); the cloud has {}",
            filename, n);
    }
    Header h;
    h.version = 4;
    h.num_points = uint32_t(n);
    h.sh_degree = a.sh_degree;
    h.fractional_bits = ChooseFractionalBits(filename, a.positions, n);
    WriteFileBytes(filename, AssembleV4(h, EncodeStreams(filename, a, h)));
}

}  // namespace io
}  // namespace t
}  // namespace open3d
