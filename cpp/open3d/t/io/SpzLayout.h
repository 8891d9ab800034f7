// Niantic SPZ, as specified by nianticlabs/spz README.md ("File Format") and implemented by
// its src/cc/load-spz.cc (commit 21715c3). All integers little endian.
//
// v4: a 32-byte plain header (magic "NGSP", version, numPoints, shDegree, fractionalBits,
// flags, numStreams, tocByteOffset, 12 reserved bytes), extension records up to
// tocByteOffset (flag 0x2), a TOC of numStreams (compressedSize, uncompressedSize) u64 pairs,
// then one zstd frame per non-empty stream in the order positions, alphas, colours, scales,
// rotations, SH. v1-3: the whole file is one gzip member holding a 16-byte header (magic,
// version, numPoints, shDegree, fractionalBits, flags, reserved) and the same six arrays
// back to back, then extension records (flag 0x2). Per splat:
//   positions  v2+: 3 x 24-bit signed fixed point, value / 2^fractionalBits; v1: 3 x float16
//   alphas     sigmoid(opacity) * 255, rounded
//   colours    f_dc * 0.15 * 255 + 127.5, rounded (the SPZ "colour scale" 0.15, not SH C0)
//   scales     (log scale + 10) * 16, rounded
//   rotations  v3+: u32, bits 30-31 the index of the largest |component| of (x, y, z, w)
//              made positive, then for the other three in index order (first one highest)
//              a sign bit and a 9-bit magnitude |q_i| / sqrt(1/2) * 511;
//              v1-2: (x, y, z) as (q_i * 127.5 + 127.5) with w >= 0 derived
//   SH         (degree+1)^2 - 1 coefficients, colour the inner axis: c * 128 + 128 rounded;
//              writers keep 5 bits for degree 1 and 4 bits for degrees 2-4 (QuantiseSH)
// SPZ stores RUB axes (x right, y up, z back); 3DGS clouds are RDF. The change is the
// rotation by 180 degrees about x: positions (x, -y, -z), quaternions (w, x, -y, -z), and
// each SH coefficient times the sign its basis function takes under (x, y, z) -> (x, -y, -z).
// The SPZ_ADOBE_coordinate_system extension may name another stored axis convention.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace open3d {
namespace t {
namespace io {
namespace spz {

inline constexpr uint32_t kMagic = 0x5053474e;  // "NGSP"
inline constexpr size_t kHeaderBytes = 32;      // v4
inline constexpr size_t kLegacyHeaderBytes = 16;
inline constexpr uint8_t kFlagAntialiased = 0x1;
inline constexpr uint8_t kFlagExtensions = 0x2;
inline constexpr int kMaxFileSHDegree = 4;  // SPZ holds up to 4; clouds here hold up to 3
inline constexpr int kMaxCloudSHDegree = 3;
inline constexpr double kColourScale = 0.15;
inline constexpr double kSqrtHalf = 0.70710678118654752440;
inline constexpr int kWriteFractionalBits = 12;      // the reference writer's choice (~0.25 mm)
inline constexpr int32_t kMaxFixed = (1 << 23) - 1;  // 24-bit signed, used symmetrically
inline constexpr int kSH1Bucket = 1 << (8 - 5);      // 5 bits for degree 1 (reference default)
inline constexpr int kSHRestBucket = 1 << (8 - 4);   // 4 bits for degrees 2-3
// alpha 0 and 255 would be logits of -inf/+inf; this margin keeps them finite and
// re-encodes to the same byte (as in the .splat reader).
inline constexpr double kAlphaMargin = 1e-6;
// A zstd block yields at most 128 KiB and takes at least 4 bytes (3-byte header + 1 RLE
// byte), so no stream can expand by more than this: larger TOC sizes are refused before
// any allocation.
inline constexpr uint64_t kZstdMaxExpansion = 32768;
// Deflate emits at most 258 bytes per 2 bits of input.
inline constexpr uint64_t kDeflateMaxExpansion = 1032;
// What a v1-3 gzip stream may hold after its attributes (the extensions, a few bytes each):
// more is not inflated.
inline constexpr uint64_t kMaxLegacyTailBytes = 1 << 20;
inline constexpr uint32_t kExtensionCoordinateSystem = 0xADBE0003;  // SPZ_ADOBE_coordinate_system
inline constexpr uint32_t kCoordinateRUB = 4, kCoordinateRDF = 6;   // spz::CoordinateSystem values

enum Stream { kPositions, kAlphas, kColours, kScales, kRotations, kSH, kNumStreams };
using Streams = std::array<std::vector<uint8_t>, kNumStreams>;
inline constexpr const char* kStreamNames[kNumStreams] = {"positions", "alphas",    "colors",
                                                          "scales",    "rotations", "sh"};

// Odd-parity axes (bit 0 x, 1 y, 2 z) of each SH basis function of SphericalHarmonics.h,
// f_rest index k = j - 1: degree 1 (y, z, x); degree 2 (xy, yz, 2zz-xx-yy, xz, xx-yy);
// degree 3 (y(3xx-yy), xyz, y(4zz-xx-yy), z(2zz-3xx-3yy), x(4zz-xx-yy), z(xx-yy),
// x(xx-3yy)). Under an axis flip a basis function picks up the product of the flipped
// signs of its odd axes.
inline constexpr uint8_t kSHOddAxes[15] = {2, 4, 1, 3, 6, 0, 5, 0, 2, 7, 2, 4, 1, 4, 1};

inline uint32_t LoadU32(const uint8_t* p) {
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
inline uint64_t LoadU64(const uint8_t* p) { return LoadU32(p) | uint64_t(LoadU32(p + 4)) << 32; }
inline void StoreU32(uint8_t* p, uint32_t v) {
    for (int i = 0; i < 4; ++i) p[i] = uint8_t(v >> (8 * i));
}
inline void StoreU64(uint8_t* p, uint64_t v) {
    StoreU32(p, uint32_t(v));
    StoreU32(p + 4, uint32_t(v >> 32));
}

/// The header fields both layouts share, and the stream sizes they imply.
struct Header {
    uint32_t version = 0;
    uint32_t num_points = 0;
    int sh_degree = 0;
    int fractional_bits = 0;
    uint8_t flags = 0;

    uint64_t BytesPerSplat(int stream) const {
        switch (stream) {
            case kPositions:
                return version == 1 ? 6 : 9;  // v1: float16
            case kAlphas:
                return 1;
            case kRotations:
                return version >= 3 ? 4 : 3;
            case kSH:
                return uint64_t(geometry::NumSHRestCoeffs(sh_degree)) * 3;
            default:
                return 3;  // colours, scales
        }
    }
    uint64_t StreamBytes(int stream) const { return num_points * BytesPerSplat(stream); }
    /// Bytes of every stream together for one splat.
    uint64_t AllStreamsBytesPerSplat() const {
        uint64_t bytes = 0;
        for (int k = 0; k < kNumStreams; ++k) bytes += BytesPerSplat(k);
        return bytes;
    }
    /// The streams a v4 file holds (the non-empty ones), in file order; returns their count.
    int PresentStreams(std::array<int, kNumStreams>& present) const {
        int count = 0;
        for (int k = 0; k < kNumStreams; ++k) {
            if (StreamBytes(k) > 0) present[count++] = k;
        }
        return count;
    }
};

/// Sign changes from the stored axes to RDF (a diagonal matrix diag(sx, sy, sz)).
struct AxisFlips {
    std::array<double, 3> position{};
    std::array<float, 3> quaternion_xyz{};  // w never changes
    std::array<float, 15> sh{};

    explicit AxisFlips(std::array<int, 3> s) {
        for (int a = 0; a < 3; ++a) position[a] = s[a];
        // R -> D R D (D = diag(s)) is (w, x, y, z) -> (w, sy sz x, sx sz y, sx sy z); for a
        // reflection (det D = -1) it is the same as for the rotation -D.
        quaternion_xyz = {float(s[1] * s[2]), float(s[0] * s[2]), float(s[0] * s[1])};
        for (int k = 0; k < 15; ++k) {
            int sign = 1;
            for (int a = 0; a < 3; ++a) {
                if (kSHOddAxes[k] & (1 << a)) sign *= s[a];
            }
            sh[k] = float(sign);
        }
    }
};

/// Flips between a stored axis convention of the standard family (spz::CoordinateSystem
/// 1..8: bit 0 of value-1 is R, bit 1 U, bit 2 F) and RDF. The map is its own inverse.
inline AxisFlips FlipsToRDF(uint32_t stored) {
    std::array<int, 3> s{};
    for (int a = 0; a < 3; ++a) {
        s[a] = (((stored - 1) >> a) & 1) == (((kCoordinateRDF - 1) >> a) & 1) ? 1 : -1;
    }
    return AxisFlips(s);
}

/// The "smallest three" rotation (v3+) as (x, y, z, w).
inline void UnpackSmallestThree(uint32_t packed, double q[4]) {
    const int largest = int(packed >> 30);
    double sum_squares = 0;
    for (int k = 3; k >= 0; --k) {  // the last component sits in the lowest bits
        if (k == largest) continue;
        const double magnitude = kSqrtHalf * (packed & 511) / 511.0;
        q[k] = (packed >> 9) & 1 ? -magnitude : magnitude;
        sum_squares += q[k] * q[k];
        packed >>= 10;
    }
    q[largest] = std::sqrt(std::max(0.0, 1.0 - sum_squares));
}

}  // namespace spz
}  // namespace io
}  // namespace t
}  // namespace open3d
