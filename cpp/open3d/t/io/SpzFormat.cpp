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

namespace open3d {
namespace t {
namespace io {
namespace {

constexpr uint32_t kMagic = 0x5053474e;  // "NGSP"
constexpr size_t kHeaderBytes = 32;      // v4
constexpr size_t kLegacyHeaderBytes = 16;
constexpr uint8_t kFlagAntialiased = 0x1;
constexpr uint8_t kFlagExtensions = 0x2;
constexpr int kMaxFileSHDegree = 4;  // SPZ holds up to 4; clouds here hold up to 3
constexpr int kMaxCloudSHDegree = 3;
constexpr double kColourScale = 0.15;
constexpr double kSqrtHalf = 0.70710678118654752440;
constexpr int kWriteFractionalBits = 12;      // the reference writer's choice (~0.25 mm)
constexpr int32_t kMaxFixed = (1 << 23) - 1;  // 24-bit signed, used symmetrically
constexpr int kSH1Bucket = 1 << (8 - 5);      // 5 bits for degree 1 (reference default)
constexpr int kSHRestBucket = 1 << (8 - 4);   // 4 bits for degrees 2-3
// alpha 0 and 255 would be logits of -inf/+inf; this margin keeps them finite and
// re-encodes to the same byte (as in the .splat reader).
constexpr double kAlphaMargin = 1e-6;
// A zstd block yields at most 128 KiB and takes at least 4 bytes (3-byte header + 1 RLE
// byte), so no stream can expand by more than this: larger TOC sizes are refused before
// any allocation.
constexpr uint64_t kZstdMaxExpansion = 32768;
// Deflate emits at most 258 bytes per 2 bits of input.
constexpr uint64_t kDeflateMaxExpansion = 1032;
constexpr uint32_t kExtensionCoordinateSystem = 0xADBE0003;  // SPZ_ADOBE_coordinate_system
constexpr uint32_t kCoordinateRUB = 4, kCoordinateRDF = 6;   // spz::CoordinateSystem values

enum Stream { kPositions, kAlphas, kColours, kScales, kRotations, kSH, kNumStreams };
using Streams = std::array<std::vector<uint8_t>, kNumStreams>;
constexpr const char* kStreamNames[kNumStreams] = {"positions", "alphas",    "colors",
                                                   "scales",    "rotations", "sh"};

// Odd-parity axes (bit 0 x, 1 y, 2 z) of each SH basis function of SphericalHarmonics.h,
// f_rest index k = j - 1: degree 1 (y, z, x); degree 2 (xy, yz, 2zz-xx-yy, xz, xx-yy);
// degree 3 (y(3xx-yy), xyz, y(4zz-xx-yy), z(2zz-3xx-3yy), x(4zz-xx-yy), z(xx-yy),
// x(xx-3yy)). Under an axis flip a basis function picks up the product of the flipped
// signs of its odd axes.
constexpr uint8_t kSHOddAxes[15] = {2, 4, 1, 3, 6, 0, 5, 0, 2, 7, 2, 4, 1, 4, 1};

uint32_t LoadU32(const uint8_t* p) {
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
uint64_t LoadU64(const uint8_t* p) { return LoadU32(p) | uint64_t(LoadU32(p + 4)) << 32; }
void StoreU32(uint8_t* p, uint32_t v) {
    for (int i = 0; i < 4; ++i) p[i] = uint8_t(v >> (8 * i));
}
void StoreU64(uint8_t* p, uint64_t v) {
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
AxisFlips FlipsToRDF(uint32_t stored) {
    std::array<int, 3> s{};
    for (int a = 0; a < 3; ++a) {
        s[a] = (((stored - 1) >> a) & 1) == (((kCoordinateRDF - 1) >> a) & 1) ? 1 : -1;
    }
    return AxisFlips(s);
}

/// Walks the extension records [u32 type][u32 length][payload] and returns the stored
/// coordinate system (RUB unless SPZ_ADOBE_coordinate_system says otherwise).
uint32_t ParseExtensions(const std::string& filename, const uint8_t* data, size_t size,
                         const char* where) {
    uint32_t stored = kCoordinateRUB;
    size_t offset = 0;
    while (offset < size) {
        if (size - offset < 8) {
            core::ThrowError(
                "'{}': SPZ extension record at byte {} of the {} is truncated ({} of 8 "
                "header bytes)",
                filename, offset, where, size - offset);
        }
        const uint32_t type = LoadU32(data + offset);
        const uint32_t length = LoadU32(data + offset + 4);
        offset += 8;
        if (length > size - offset) {
            core::ThrowError(
                "'{}': SPZ extension record 0x{:08x}: byteLength {} passes the end of "
                "the {} ({} bytes left)",
                filename, type, length, where, size - offset);
        }
        if (type == kExtensionCoordinateSystem) {
            const uint32_t value = length >= 4 ? LoadU32(data + offset) : 0;
            if (length != 4 || value > 16) {
                core::ThrowError(
                    "'{}': SPZ_ADOBE_coordinate_system extension: payload of {} "
                    "bytes / value {} (expected 4 bytes holding 0..16)",
                    filename, length, value);
            }
            if (value == 0) {
                core::LogWarning("'{}': SPZ_ADOBE_coordinate_system is UNSPECIFIED; assuming RUB",
                                 filename);
            } else if (value > 8) {
                core::ThrowError(
                    "'{}': SPZ_ADOBE_coordinate_system value {} is an axis order "
                    "rotated 90 degrees about x; only the axis-flip family (1..8) "
                    "is supported",
                    filename, value);
            } else {
                stored = value;
            }
        } else {
            core::LogWarning("'{}': skipped unknown SPZ extension 0x{:08x} ({} bytes)", filename,
                             type, length);
        }
        offset += length;
    }
    return stored;
}

float HalfToFloat(uint16_t h) {
    const int exponent = (h >> 10) & 31, mantissa = h & 1023;
    double v;
    if (exponent == 0) {
        v = std::ldexp(double(mantissa), -24);
    } else if (exponent == 31) {
        v = mantissa ? std::numeric_limits<double>::quiet_NaN()
                     : std::numeric_limits<double>::infinity();
    } else {
        v = std::ldexp(double(mantissa + 1024), exponent - 25);
    }
    return float((h & 0x8000) ? -v : v);
}

/// The "smallest three" rotation (v3+) as (x, y, z, w).
void UnpackSmallestThree(uint32_t packed, double q[4]) {
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

/// Decodes the six attribute arrays (`streams[k]` holds StreamBytes(k) bytes) into the
/// columns, applying the axis change, and hands them to FinalizeColumns.
geometry::PointCloud DecodeSplats(const std::string& filename, const Header& h,
                                  const std::array<const uint8_t*, kNumStreams>& streams,
                                  const AxisFlips& flips, const ReadPointCloudOptions& options,
                                  ReadPointCloudReport& report) {
    if (h.flags & kFlagAntialiased) {
        core::LogWarning(
            "'{}': SPZ flag 'antialiased' is set (trained with mip-splatting antialiasing): "
            "render it with antialiasing on",
            filename);
    }
    const int degree = std::min(h.sh_degree, kMaxCloudSHDegree);
    if (h.sh_degree > kMaxCloudSHDegree) {
        core::LogWarning(
            "'{}': SH degree {} holds more than the 3 bands a cloud can; band 4 "
            "is dropped",
            filename, h.sh_degree);
    }
    const int64_t n = h.num_points;
    const int nc = geometry::NumSHRestCoeffs(degree),
              file_nc = geometry::NumSHRestCoeffs(h.sh_degree);
    SplatColumns c;
    c.Allocate(n, /*gaussian=*/true, degree);
    float* positions = c.positions.Data<float>();
    float* scale = c.scale.Data<float>();
    float* rot = c.rot.Data<float>();
    float* opacity = c.opacity.Data<float>();
    float* f_dc = c.f_dc.Data<float>();
    float* f_rest = nc > 0 ? c.f_rest.Data<float>() : nullptr;
    const double position_scale = std::ldexp(1.0, -h.fractional_bits);
    const bool float16 = h.version == 1, smallest_three = h.version >= 3;
    core::ParallelFor(
        n,
        [&](int64_t i) {
            for (int a = 0; a < 3; ++a) {
                double v;
                if (float16) {
                    const uint8_t* p = streams[kPositions] + i * 6 + a * 2;
                    v = HalfToFloat(uint16_t(p[0] | p[1] << 8));
                } else {
                    const uint8_t* p = streams[kPositions] + i * 9 + a * 3;
                    int32_t fixed = int32_t(p[0] | p[1] << 8 | p[2] << 16);
                    if (fixed & 0x800000) fixed -= 1 << 24;  // sign extension
                    v = fixed * position_scale;
                }
                positions[i * 3 + a] = float(v * flips.position[a]);
            }
            const double alpha =
                std::clamp(streams[kAlphas][i] / 255.0, kAlphaMargin, 1.0 - kAlphaMargin);
            opacity[i] = float(std::log(alpha / (1.0 - alpha)));
            for (int a = 0; a < 3; ++a) {
                f_dc[i * 3 + a] =
                    float((streams[kColours][i * 3 + a] / 255.0 - 0.5) / kColourScale);
                scale[i * 3 + a] = DecodeLogScale(float(streams[kScales][i * 3 + a] / 16.0 - 10.0));
            }
            double q[4];  // x, y, z, w as SPZ orders them
            if (smallest_three) {
                UnpackSmallestThree(LoadU32(streams[kRotations] + i * 4), q);
            } else {
                const uint8_t* r = streams[kRotations] + i * 3;
                for (int k = 0; k < 3; ++k) q[k] = r[k] / 127.5 - 1.0;
                q[3] = std::sqrt(std::max(0.0, 1.0 - q[0] * q[0] - q[1] * q[1] - q[2] * q[2]));
            }
            rot[i * 4] = float(q[3]);
            for (int k = 0; k < 3; ++k) rot[i * 4 + 1 + k] = float(q[k]) * flips.quaternion_xyz[k];
            if (nc == 0) return;
            const uint8_t* sh = streams[kSH] + i * file_nc * 3;
            for (int k = 0; k < nc; ++k) {
                for (int ch = 0; ch < 3; ++ch) {
                    f_rest[(i * nc + k) * 3 + ch] =
                        float((sh[k * 3 + ch] - 128) / 128.0) * flips.sh[k];
                }
            }
        },
        4096);
    return FinalizeColumns(filename, c, options, report);
}

void CheckHeader(const std::string& filename, const Header& h) {
    if (h.sh_degree > kMaxFileSHDegree) {
        core::ThrowError("'{}': SPZ header field 'shDegree' is {}; SPZ defines 0..4", filename,
                         h.sh_degree);
    }
}

geometry::PointCloud ReadLegacy(const std::string& filename, const uint8_t* file, size_t size,
                                const ReadPointCloudOptions& options,
                                ReadPointCloudReport& report) {
    const std::vector<uint8_t> bytes = GunzipBytes(file, size, size * kDeflateMaxExpansion + 1024,
                                                   fmt::format("'{}': SPZ gzip stream", filename));
    if (bytes.size() < kLegacyHeaderBytes) {
        core::ThrowError(
            "'{}': truncated SPZ header: the gzip stream holds {} bytes, the v1-3 "
            "header needs {}",
            filename, bytes.size(), kLegacyHeaderBytes);
    }
    if (LoadU32(bytes.data()) != kMagic) {
        core::ThrowError(
            "'{}': SPZ header field 'magic' is 0x{:08x} inside the gzip stream, "
            "expected 0x{:08x} (\"NGSP\")",
            filename, LoadU32(bytes.data()), kMagic);
    }
    Header h;
    h.version = LoadU32(bytes.data() + 4);
    h.num_points = LoadU32(bytes.data() + 8);
    h.sh_degree = bytes[12];
    h.fractional_bits = bytes[13];
    h.flags = bytes[14];
    if (h.version < 1 || h.version > 3) {
        core::ThrowError(
            "'{}': SPZ header field 'version' is {} in a gzip stream; gzip holds "
            "versions 1-3 (version 4 is not gzip-compressed)",
            filename, h.version);
    }
    CheckHeader(filename, h);
    uint64_t offset = kLegacyHeaderBytes, per_splat = 0;
    for (int k = 0; k < kNumStreams; ++k) {
        offset += h.StreamBytes(k);
        per_splat += h.BytesPerSplat(k);
    }
    if (offset > bytes.size()) {
        core::ThrowError(
            "'{}': SPZ header field 'numPoints' is {}: that needs {} bytes of "
            "attributes ({} per splat), the gzip stream holds {} after the header",
            filename, h.num_points, offset - kLegacyHeaderBytes, per_splat,
            bytes.size() - kLegacyHeaderBytes);
    }
    std::array<const uint8_t*, kNumStreams> streams{};
    streams[0] = bytes.data() + kLegacyHeaderBytes;
    for (int k = 1; k < kNumStreams; ++k) streams[k] = streams[k - 1] + h.StreamBytes(k - 1);
    const size_t extra = bytes.size() - offset;
    uint32_t stored = kCoordinateRUB;
    if (h.flags & kFlagExtensions) {
        stored = ParseExtensions(filename, bytes.data() + offset, extra, "gzip stream");
    } else if (extra > 0) {
        core::LogWarning("'{}': {} bytes after the SPZ attributes ignored", filename, extra);
        report.trailing_bytes = int64_t(extra);
    }
    return DecodeSplats(filename, h, streams, FlipsToRDF(stored), options, report);
}

geometry::PointCloud ReadV4(const std::string& filename, const uint8_t* file, size_t size,
                            const ReadPointCloudOptions& options, ReadPointCloudReport& report) {
    if (size < kHeaderBytes) {
        core::ThrowError("'{}': truncated SPZ header: {} bytes, the header needs {}", filename,
                         size, kHeaderBytes);
    }
    Header h;
    h.version = LoadU32(file + 4);
    h.num_points = LoadU32(file + 8);
    h.sh_degree = file[12];
    h.fractional_bits = file[13];
    h.flags = file[14];
    const int num_streams = file[15];
    const uint32_t toc_offset = LoadU32(file + 16);
    if (h.version >= 1 && h.version <= 3) {
        core::ThrowError(
            "'{}': SPZ header field 'version' is {} but the file is not "
            "gzip-compressed: the spec stores versions 1-3 as gzip streams only",
            filename, h.version);
    }
    if (h.version != 4) {
        core::ThrowError("'{}': SPZ header field 'version' is {}; supported are 1-4", filename,
                         h.version);
    }
    CheckHeader(filename, h);
    std::array<int, kNumStreams> present{};
    const int expected_streams = h.PresentStreams(present);
    if (num_streams != expected_streams) {
        core::ThrowError(
            "'{}': SPZ header field 'numStreams' is {}; numPoints {} with shDegree "
            "{} needs {}",
            filename, num_streams, h.num_points, h.sh_degree, expected_streams);
    }
    const uint64_t toc_end = uint64_t(toc_offset) + uint64_t(num_streams) * 16;
    if (toc_offset < kHeaderBytes || toc_end > size) {
        core::ThrowError(
            "'{}': SPZ header field 'tocByteOffset' is {}: the TOC of {} streams "
            "must lie between byte {} and the end of the file ({} bytes)",
            filename, toc_offset, num_streams, kHeaderBytes, size);
    }
    uint32_t stored = kCoordinateRUB;
    if (h.flags & kFlagExtensions) {
        stored = ParseExtensions(filename, file + kHeaderBytes, toc_offset - kHeaderBytes,
                                 "header zone");
    }
    // The whole TOC is checked before anything is decompressed.
    std::array<uint64_t, kNumStreams> offsets{}, sizes{};
    std::array<std::string, kNumStreams> names;
    uint64_t offset = toc_end;
    for (int s = 0; s < num_streams; ++s) {
        const int k = present[s];
        const uint64_t compressed = LoadU64(file + toc_offset + s * 16);
        const uint64_t uncompressed = LoadU64(file + toc_offset + s * 16 + 8);
        names[s] = fmt::format("'{}': SPZ stream {} ({}) at byte {}", filename, s, kStreamNames[k],
                               offset);
        if (compressed > size - offset) {
            core::ThrowError("{}: TOC compressedSize {} passes the end of the file ({} bytes)",
                             names[s], compressed, size);
        }
        if (uncompressed != h.StreamBytes(k)) {
            core::ThrowError(
                "{}: TOC uncompressedSize is {}, but numPoints {} needs {} ({} bytes per "
                "splat)",
                names[s], uncompressed, h.num_points, h.StreamBytes(k), h.BytesPerSplat(k));
        }
        if (uncompressed > compressed * kZstdMaxExpansion) {
            core::ThrowError(
                "{}: {} compressed bytes cannot hold the {} bytes numPoints {} needs (zstd "
                "expands at most {}x)",
                names[s], compressed, uncompressed, h.num_points, kZstdMaxExpansion);
        }
        offsets[s] = offset;
        sizes[s] = compressed;
        offset += compressed;
    }
    if (offset < size) {
        core::LogWarning("'{}': {} bytes after the last SPZ stream ignored", filename,
                         size - offset);
        report.trailing_bytes = int64_t(size - offset);
    }
    std::array<std::vector<uint8_t>, kNumStreams> decoded;
    std::array<const uint8_t*, kNumStreams> streams{};
    for (int s = 0; s < num_streams; ++s) {
        const int k = present[s];
        const uint8_t* frame = file + offsets[s];
        // A single frame that declares its size is checked before anything is allocated.
        const unsigned long long declared = ZSTD_getFrameContentSize(frame, sizes[s]);
        if (ZSTD_findFrameCompressedSize(frame, sizes[s]) == sizes[s] &&
            declared != ZSTD_CONTENTSIZE_UNKNOWN && declared != ZSTD_CONTENTSIZE_ERROR &&
            declared != h.StreamBytes(k)) {
            core::ThrowError(
                "{}: the zstd frame holds {} bytes, the TOC's uncompressedSize (and numPoints) "
                "say {}",
                names[s], declared, h.StreamBytes(k));
        }
        decoded[k] = ZstdDecompressBytes(frame, sizes[s], h.StreamBytes(k), names[s]);
        streams[k] = decoded[k].data();
    }
    return DecodeSplats(filename, h, streams, FlipsToRDF(stored), options, report);
}

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

geometry::PointCloud ReadSpz(const std::string& filename, const ReadPointCloudOptions& options,
                             ReadPointCloudReport& report) {
    const MappedFile file(filename);
    const uint8_t* data = file.data();
    if (file.size() >= 2 && data[0] == 0x1f && data[1] == 0x8b) {
        return ReadLegacy(filename, data, file.size(), options, report);
    }
    if (file.size() < 4 || LoadU32(data) != kMagic) {
        core::ThrowError(
            "'{}': SPZ header field 'magic' is not \"NGSP\" and the file is not "
            "gzip-compressed (SPZ v1-3)",
            filename);
    }
    return ReadV4(filename, data, file.size(), options, report);
}

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
