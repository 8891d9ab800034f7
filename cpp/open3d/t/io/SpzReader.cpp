// The SPZ reader (layout and choices: SpzLayout.h).
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

// What is decoded: `filename` for the memory check, `label` opens every message (the quoted
// file name, or a glTF file and the JSON path of its SPZ), and whether the axes are handed out
// as stored or converted to RDF.
struct Source {
    const std::string& filename;
    std::string label;
    SpzAxes axes;
};

/// Walks the extension records [u32 type][u32 length][payload] and returns the stored
/// coordinate system (RUB unless SPZ_ADOBE_coordinate_system says otherwise).
uint32_t ParseExtensions(const Source& src, const uint8_t* data, size_t size, const char* where) {
    uint32_t stored = kCoordinateRUB;
    size_t offset = 0;
    while (offset < size) {
        if (size - offset < 8) {
            core::ThrowError(
                "{}: SPZ extension record at byte {} of the {} is truncated ({} of 8 "
                "header bytes)",
                src.label, offset, where, size - offset);
        }
        const uint32_t type = LoadU32(data + offset);
        const uint32_t length = LoadU32(data + offset + 4);
        offset += 8;
        if (length > size - offset) {
            core::ThrowError(
                "{}: SPZ extension record 0x{:08x}: byteLength {} passes the end of "
                "the {} ({} bytes left)",
                src.label, type, length, where, size - offset);
        }
        if (type == kExtensionCoordinateSystem) {
            const uint32_t value = length >= 4 ? LoadU32(data + offset) : 0;
            if (length != 4 || value > 16) {
                core::ThrowError(
                    "{}: SPZ_ADOBE_coordinate_system extension: payload of {} "
                    "bytes / value {} (expected 4 bytes holding 0..16)",
                    src.label, length, value);
            }
            if (src.axes == SpzAxes::kAsStored) {
                // glTF takes the values as stored (FileFormats.h); the record changes nothing.
                core::LogWarning(
                    "{}: SPZ_ADOBE_coordinate_system value {} ignored: the values are read as "
                    "stored",
                    src.label, value);
            } else if (value == 0) {
                core::LogWarning("{}: SPZ_ADOBE_coordinate_system is UNSPECIFIED; assuming RUB",
                                 src.label);
            } else if (value > 8) {
                core::ThrowError(
                    "{}: SPZ_ADOBE_coordinate_system value {} is an axis order "
                    "rotated 90 degrees about x; only the axis-flip family (1..8) "
                    "is supported",
                    src.label, value);
            } else {
                stored = value;
            }
        } else {
            core::LogWarning("{}: skipped unknown SPZ extension 0x{:08x} ({} bytes)", src.label,
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

/// Decodes the six attribute arrays (`streams[k]` holds StreamBytes(k) bytes) into the
/// columns, applying the axis change from the `stored` convention unless kept as stored.
void DecodeSplats(const Source& src, const Header& h,
                  const std::array<const uint8_t*, kNumStreams>& streams, uint32_t stored,
                  SplatColumns& c) {
    const AxisFlips flips =
        src.axes == SpzAxes::kAsStored ? AxisFlips({1, 1, 1}) : FlipsToRDF(stored);
    if (h.flags & kFlagAntialiased) {
        core::LogWarning(
            "{}: SPZ flag 'antialiased' is set (trained with mip-splatting antialiasing): "
            "render it with antialiasing on",
            src.label);
    }
    const int degree = std::min(h.sh_degree, kMaxCloudSHDegree);
    if (h.sh_degree > kMaxCloudSHDegree) {
        core::LogWarning(
            "{}: SH degree {} holds more than the 3 bands a cloud can; band 4 "
            "is dropped",
            src.label, h.sh_degree);
    }
    const int64_t n = h.num_points;
    const int nc = geometry::NumSHRestCoeffs(degree),
              file_nc = geometry::NumSHRestCoeffs(h.sh_degree);
    c.Allocate(src.filename, n, /*gaussian=*/true, degree);
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
}

// The decoded cloud and the decompressed streams held while it is filled
// must fit before anything is decompressed: a 61 KB file of RLE zstd frames claiming 1e8
// splats was refused only after 11 s of decoding at 2 GB.
void CheckDecodeMemory(const Source& src, const Header& h) {
    CheckSplatColumnsMemory(src.filename, int64_t(h.num_points), /*gaussian=*/true,
                            std::min(h.sh_degree, kMaxCloudSHDegree), h.AllStreamsBytesPerSplat(),
                            "bytes of decompressed streams");
}

void CheckHeader(const Source& src, const Header& h) {
    if (h.sh_degree > kMaxFileSHDegree) {
        core::ThrowError("{}: SPZ header field 'shDegree' is {}; SPZ defines 0..4", src.label,
                         h.sh_degree);
    }
    // Positions are 24-bit fixed point over 2^fractionalBits; the reference reader divides by
    // (1 << fractionalBits) in a 32-bit int, so 31 and more are no scale it can read (40
    // would put every splat at the origin).
    if (h.fractional_bits > 30) {
        core::ThrowError("{}: SPZ header field 'fractionalBits' is {}; SPZ positions take 0..30",
                         src.label, h.fractional_bits);
    }
}

void ReadLegacy(const Source& src, const uint8_t* file, size_t size, SplatColumns& columns,
                ReadPointCloudReport& report) {
    // The header first, alone: numPoints bounds what the rest may inflate to, and the memory
    // check runs before that (a 2 MB gzip bomb named .spz once inflated 2 GiB first).
    bool more = false;
    const std::vector<uint8_t> head = GunzipPrefixBytes(
        file, size, kLegacyHeaderBytes, &more, fmt::format("{}: SPZ gzip stream", src.label));
    if (head.size() < kLegacyHeaderBytes) {
        core::ThrowError(
            "{}: truncated SPZ header: the gzip stream holds {} bytes, the v1-3 "
            "header needs {}",
            src.label, head.size(), kLegacyHeaderBytes);
    }
    if (LoadU32(head.data()) != kMagic) {
        core::ThrowError(
            "{}: SPZ header field 'magic' is 0x{:08x} inside the gzip stream, "
            "expected 0x{:08x} (\"NGSP\")",
            src.label, LoadU32(head.data()), kMagic);
    }
    Header h;
    h.version = LoadU32(head.data() + 4);
    h.num_points = LoadU32(head.data() + 8);
    h.sh_degree = head[12];
    h.fractional_bits = head[13];
    h.flags = head[14];
    if (h.version < 1 || h.version > 3) {
        core::ThrowError(
            "{}: SPZ header field 'version' is {} in a gzip stream; gzip holds "
            "versions 1-3 (version 4 is not gzip-compressed)",
            src.label, h.version);
    }
    CheckHeader(src, h);
    const uint64_t per_splat = h.AllStreamsBytesPerSplat();
    const uint64_t attribute_bytes = uint64_t(h.num_points) * per_splat;
    CheckDecodeMemory(src, h);
    // Extensions follow the attributes inside the stream; more than kMaxLegacyTailBytes
    // after them is not read (a warning says so).
    const uint64_t wanted =
        std::min<uint64_t>(kLegacyHeaderBytes + attribute_bytes + kMaxLegacyTailBytes,
                           uint64_t(size) * kDeflateMaxExpansion + 1024);
    const std::vector<uint8_t> bytes = GunzipPrefixBytes(
        file, size, size_t(wanted), &more, fmt::format("{}: SPZ gzip stream", src.label));
    if (more) {
        core::LogWarning(
            "{}: the gzip stream goes on past {} bytes after the SPZ attributes; "
            "the rest is not read",
            src.label, kMaxLegacyTailBytes);
    }
    const uint64_t offset = kLegacyHeaderBytes + attribute_bytes;
    if (offset > bytes.size()) {
        core::ThrowError(
            "{}: SPZ header field 'numPoints' is {}: that needs {} bytes of "
            "attributes ({} per splat), the gzip stream holds {} after the header",
            src.label, h.num_points, offset - kLegacyHeaderBytes, per_splat,
            bytes.size() - kLegacyHeaderBytes);
    }
    std::array<const uint8_t*, kNumStreams> streams{};
    streams[0] = bytes.data() + kLegacyHeaderBytes;
    for (int k = 1; k < kNumStreams; ++k) streams[k] = streams[k - 1] + h.StreamBytes(k - 1);
    const size_t extra = bytes.size() - offset;
    uint32_t stored = kCoordinateRUB;
    if (h.flags & kFlagExtensions) {
        stored = ParseExtensions(src, bytes.data() + offset, extra, "gzip stream");
    } else if (extra > 0) {
        core::LogWarning("{}: {} bytes after the SPZ attributes ignored", src.label, extra);
        report.trailing_bytes = int64_t(extra);
    }
    DecodeSplats(src, h, streams, stored, columns);
}

void ReadV4(const Source& src, const uint8_t* file, size_t size, SplatColumns& columns,
            ReadPointCloudReport& report) {
    if (size < kHeaderBytes) {
        core::ThrowError("{}: truncated SPZ header: {} bytes, the header needs {}", src.label, size,
                         kHeaderBytes);
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
            "{}: SPZ header field 'version' is {} but the data is not "
            "gzip-compressed: the spec stores versions 1-3 as gzip streams only",
            src.label, h.version);
    }
    if (h.version != 4) {
        core::ThrowError("{}: SPZ header field 'version' is {}; supported are 1-4", src.label,
                         h.version);
    }
    CheckHeader(src, h);
    std::array<int, kNumStreams> present{};
    const int expected_streams = h.PresentStreams(present);
    if (num_streams != expected_streams) {
        core::ThrowError(
            "{}: SPZ header field 'numStreams' is {}; numPoints {} with shDegree "
            "{} needs {}",
            src.label, num_streams, h.num_points, h.sh_degree, expected_streams);
    }
    const uint64_t toc_end = uint64_t(toc_offset) + uint64_t(num_streams) * 16;
    if (toc_offset < kHeaderBytes || toc_end > size) {
        core::ThrowError(
            "{}: SPZ header field 'tocByteOffset' is {}: the TOC of {} streams "
            "must lie between byte {} and the end of the SPZ data ({} bytes)",
            src.label, toc_offset, num_streams, kHeaderBytes, size);
    }
    uint32_t stored = kCoordinateRUB;
    if (h.flags & kFlagExtensions) {
        stored =
            ParseExtensions(src, file + kHeaderBytes, toc_offset - kHeaderBytes, "header zone");
    }
    // The whole TOC is checked before anything is decompressed.
    std::array<uint64_t, kNumStreams> offsets{}, sizes{};
    std::array<std::string, kNumStreams> names;
    uint64_t offset = toc_end;
    for (int s = 0; s < num_streams; ++s) {
        const int k = present[s];
        const uint64_t compressed = LoadU64(file + toc_offset + s * 16);
        const uint64_t uncompressed = LoadU64(file + toc_offset + s * 16 + 8);
        names[s] =
            fmt::format("{}: SPZ stream {} ({}) at byte {}", src.label, s, kStreamNames[k], offset);
        if (compressed > size - offset) {
            core::ThrowError("{}: TOC compressedSize {} passes the end of the SPZ data ({} bytes)",
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
        core::LogWarning("{}: {} bytes after the last SPZ stream ignored", src.label,
                         size - offset);
        report.trailing_bytes = int64_t(size - offset);
    }
    CheckDecodeMemory(src, h);
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
    DecodeSplats(src, h, streams, stored, columns);
}

}  // namespace

void DecodeSpz(const uint8_t* data, size_t size, const std::string& filename,
               const std::string& label, SpzAxes axes, SplatColumns& columns,
               ReadPointCloudReport& report) {
    const Source src{filename, label, axes};
    if (size >= 2 && data[0] == 0x1f && data[1] == 0x8b) {
        ReadLegacy(src, data, size, columns, report);
        return;
    }
    if (size < 4 || LoadU32(data) != kMagic) {
        core::ThrowError(
            "{}: SPZ header field 'magic' is not \"NGSP\" and the data is not "
            "gzip-compressed (SPZ v1-3)",
            label);
    }
    ReadV4(src, data, size, columns, report);
}

geometry::PointCloud ReadSpz(const std::string& filename, const ReadPointCloudOptions& options,
                             ReadPointCloudReport& report) {
    SplatColumns columns;
    {
        const MappedFile file(filename);
        DecodeSpz(file.data(), file.size(), filename, fmt::format("'{}'", filename),
                  SpzAxes::kToRdf, columns, report);
    }
    return FinalizeColumns(filename, columns, options, report);
}

}  // namespace io
}  // namespace t
}  // namespace open3d
