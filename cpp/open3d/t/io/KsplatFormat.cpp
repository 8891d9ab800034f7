// .ksplat (mkkellogg/GaussianSplats3D's SplatBuffer), compression modes 0, 1 and 2: reader.
//
// There is no specification. What this file relies on, and where it comes from:
//   - mkkellogg/GaussianSplats3D src/loaders/SplatBuffer.js (release 0.4.7): parseHeader,
//     parseSectionHeaders, CompressionLevels, getBucketIndex, fillSplatCenterArray,
//     fillSplatScaleRotationArray, fillSphericalHarmonicsArray (reading) and
//     writeSplatDataToSectionBuffer, generateFromUncompressedSplatArrays (writing);
//     src/loaders/ksplat/KSplatLoader.js checkVersion;
//   - playcanvas/splat-transform src/lib/readers/read-ksplat.ts, a second reader.
//
// Layout, all little endian:
//   main header, 4096 bytes: u8 version major @0 (0), u8 minor @1 (>= 1), u32 maxSectionCount
//     @4, u32 sectionCount @8, u32 maxSplatCount @12, u32 splatCount @16, u16 compression
//     mode @20, f32 scene centre @24, f32 min / max SH coefficient @36 / @40 (mode 2; 0 or
//     NaN mean -1.5 / +1.5). Only maxSectionCount, splatCount and the mode are needed (a
//     file written by splat-transform's fixture script leaves sectionCount and maxSplatCount
//     zero, and read-ksplat.ts reads only those three).
//   maxSectionCount section headers, 1024 bytes each: u32 splatCount @0, u32 maxSplatCount
//     @4, u32 bucketSize @8, u32 bucketCount @12, f32 bucketBlockSize @16, u16
//     bucketStorageSizeBytes @20, u32 compressionScaleRange @24 (0 means 1 in mode 0, 32767
//     in modes 1-2), u32 fullBucketCount @32, u32 partiallyFilledBucketCount @36, u16 SH
//     degree @40 (0, 1 or 2).
//   then each section's data in turn: partiallyFilledBucketCount u32 bucket lengths,
//     bucketCount * bucketStorageSizeBytes of buckets (each starts with its f32 centre x, y,
//     z; the centres are read at a 12-byte stride, as both readers do), then maxSplatCount
//     splat records, of which the first splatCount are used.
//   splat record, mode 0: centre f32 x3 @0, scale f32 x3 @12, rotation f32 x4 @24, colour
//     u8 x4 @40, SH f32 @44; modes 1-2: centre u16 x3 @0, scale f16 x3 @6, rotation f16 x4
//     @12, colour u8 x4 @20, SH @24 as f16 (mode 1) or u8 (mode 2); 9 SH values at degree 1,
//     24 at degree 2 (44 / 80 / 140, 24 / 42 / 72, 24 / 33 / 48 bytes per splat).
//   centre, modes 1-2: (u16 - range) * (bucketBlockSize / 2 / range) + the bucket's centre;
//     the splat with local index j is in bucket j / bucketSize while j < fullBucketCount *
//     bucketSize, after that in the partially filled buckets in order, by their lengths.
//   scale: linear (the PLY's exp(log-scale)). rotation: (w, x, y, z), as rot_0..rot_3.
//   colour: r, g, b = 255 * (0.5 + SH_C0 * f_dc), a = 255 * sigmoid(opacity), rounded.
//   SH: the degree-1 band first as R c1 c2 c3, G c1 c2 c3, B c1 c2 c3, then the degree-2
//     band as R c4..c8, G c4..c8, B c4..c8 (c = the 3DGS coefficient index); mode 2 decodes
//     a byte v as v / 255 * (max - min) + min.
//   Axes: those of the PLY the file was made from; nothing is converted.
//
// Decisions: values are computed in double and rounded to float32 once, as the JavaScript
// readers do. f_dc = (byte / 255 - 0.5) / SH_C0 and opacity = logit(byte / 255) with the
// alpha clamped to [1e-6, 1 - 1e-6] (read-ksplat.ts; our .splat reader does the same).
// Negative scales are stored as their absolute value (the covariance uses the square).
// The SH degree of the cloud is the highest of the sections that hold splats; sections of
// lower degree get zeros. Every count and offset is checked against the file before
// anything is allocated; the section splat counts must add up to the header's splatCount.

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

using geometry::kSH_C0;
using geometry::NumSHRestCoeffs;

constexpr uint64_t kMainHeaderBytes = 4096;
constexpr uint64_t kSectionHeaderBytes = 1024;
constexpr uint64_t kBucketCentreBytes = 12;
constexpr double kAlphaMargin = 1e-6;
constexpr double kDefaultSHHalfRange = 1.5;  // Constants.SphericalHarmonics8BitCompressionRange / 2

template <typename T>
T Load(const uint8_t* p) {
    T value;
    std::memcpy(&value, p, sizeof(T));
    return value;
}

float HalfToFloat(uint16_t h) {
    const uint32_t sign = static_cast<uint32_t>(h >> 15) << 31;
    const int exponent = (h >> 10) & 0x1f;
    const uint32_t mantissa = h & 0x3ff;
    uint32_t bits;
    if (exponent == 0x1f) {
        bits = sign | 0x7f800000u | (mantissa << 13);  // inf or NaN
    } else if (exponent != 0) {
        bits = sign | static_cast<uint32_t>(exponent - 15 + 127) << 23 | (mantissa << 13);
    } else {  // zero or subnormal: mantissa * 2^-24, exact in float
        const float magnitude = std::ldexp(static_cast<float>(mantissa), -24);
        return sign ? -magnitude : magnitude;
    }
    float value;
    std::memcpy(&value, &bits, 4);
    return value;
}

struct Mode {
    int centre_bytes, scale_bytes, rotation_bytes, sh_bytes;  // per value
    uint32_t default_range;
};
// SplatBuffer.CompressionLevels.
constexpr Mode kModes[3] = {{4, 4, 4, 4, 1}, {2, 2, 2, 2, 32767}, {2, 2, 2, 1, 32767}};

struct Section {
    uint64_t splats = 0, max_splats = 0, bytes_per_splat = 0;
    uint64_t data_offset = 0;  // first splat record
    uint64_t partial_offset = 0, centres_offset = 0;
    uint64_t bucket_size = 0, bucket_count = 0, full_buckets = 0, partial_buckets = 0;
    double position_scale = 0.0;
    uint32_t range = 0;
    int degree = 0;
    int64_t first = 0;  // index of its first splat in the cloud
};

// Index into the SH values of a record for coefficient k (0-based, k < 8) of channel ch.
int RecordSHIndex(int k, int ch) { return k < 3 ? ch * 3 + k : 9 + ch * 5 + (k - 3); }

}  // namespace

bool LooksLikeKsplat(const uint8_t* bytes, uint64_t size) {
    if (size < kMainHeaderBytes || bytes[0] != 0 || bytes[1] < 1) return false;
    if (Load<uint16_t>(bytes + 20) > 2 || Load<uint32_t>(bytes + 16) == 0) return false;
    return std::all_of(bytes + 44, bytes + kMainHeaderBytes, [](uint8_t b) { return b == 0; });
}

geometry::PointCloud ReadKsplat(const std::string& filename, const ReadPointCloudOptions& options,
                                ReadPointCloudReport& report) {
    const MappedFile file(filename);
    const uint8_t* bytes = file.data();
    const uint64_t size = file.size();
    if (size < kMainHeaderBytes) {
        core::ThrowError("'{}': {} bytes; a .ksplat starts with a {}-byte header (truncated file)",
                         filename, size, kMainHeaderBytes);
    }
    const int major = bytes[0], minor = bytes[1];
    if (major != 0 || minor < 1) {
        core::ThrowError(
            "'{}': .ksplat version {}.{} is not supported (GaussianSplats3D writes 0.1; major "
            "version 0, minor >= 1 is read)",
            filename, major, minor);
    }
    const uint64_t max_sections = Load<uint32_t>(bytes + 4);
    const uint64_t header_splats = Load<uint32_t>(bytes + 16);
    const int mode_index = Load<uint16_t>(bytes + 20);
    if (mode_index > 2) {
        core::ThrowError("'{}': main header: compression mode {} (0, 1 or 2 expected)", filename,
                         mode_index);
    }
    const Mode& mode = kModes[mode_index];
    float sh_min = Load<float>(bytes + 36), sh_max = Load<float>(bytes + 40);
    if (sh_min == 0.0f || std::isnan(sh_min)) sh_min = -kDefaultSHHalfRange;  // JS `|| -1.5`
    if (sh_max == 0.0f || std::isnan(sh_max)) sh_max = kDefaultSHHalfRange;
    if (max_sections > (size - kMainHeaderBytes) / kSectionHeaderBytes) {
        core::ThrowError(
            "'{}': main header: {} sections, but the file has room for at most {} section "
            "headers of {} bytes",
            filename, max_sections, (size - kMainHeaderBytes) / kSectionHeaderBytes,
            kSectionHeaderBytes);
    }

    // Section headers, and where each section's data lies; everything checked against the file.
    std::vector<Section> sections(max_sections);
    uint64_t offset = kMainHeaderBytes + max_sections * kSectionHeaderBytes;
    int64_t total = 0;
    int degree = 0;
    for (uint64_t s = 0; s < max_sections; ++s) {
        const uint8_t* h = bytes + kMainHeaderBytes + s * kSectionHeaderBytes;
        Section& sec = sections[s];
        auto fail = [&](const std::string& why) {
            core::ThrowError("'{}': section {}: {}", filename, s, why);
        };
        sec.splats = Load<uint32_t>(h + 0);
        sec.max_splats = Load<uint32_t>(h + 4);
        sec.bucket_size = Load<uint32_t>(h + 8);
        sec.bucket_count = Load<uint32_t>(h + 12);
        const float block_size = Load<float>(h + 16);
        const uint64_t bucket_storage = Load<uint16_t>(h + 20);
        sec.range = Load<uint32_t>(h + 24);
        if (sec.range == 0) sec.range = mode.default_range;
        sec.full_buckets = Load<uint32_t>(h + 32);
        sec.partial_buckets = Load<uint32_t>(h + 36);
        sec.degree = Load<uint16_t>(h + 40);
        if (sec.degree > 2) {
            fail(fmt::format("SH degree {}; GaussianSplats3D's layout holds degrees 0 to 2",
                             sec.degree));
        }
        if (sec.splats > sec.max_splats) {
            fail(fmt::format("splatCount {} exceeds maxSplatCount {}", sec.splats, sec.max_splats));
        }
        const int num_sh = 3 * NumSHRestCoeffs(sec.degree);
        sec.bytes_per_splat = 3 * mode.centre_bytes + 3 * mode.scale_bytes +
                              4 * mode.rotation_bytes + 4 + num_sh * mode.sh_bytes;
        // Sizes in 64 bits: the factors are at most 2^32 and 2^16, the file far smaller.
        const uint64_t partial_bytes = sec.partial_buckets * 4;
        const uint64_t bucket_bytes = bucket_storage * sec.bucket_count;
        const uint64_t splat_bytes = sec.bytes_per_splat * sec.max_splats;
        const uint64_t remaining = size - offset;
        if (partial_bytes > remaining || bucket_bytes > remaining - partial_bytes ||
            splat_bytes > remaining - partial_bytes - bucket_bytes) {
            fail(fmt::format(
                "{} partial bucket lengths, {} buckets of {} bytes and {} splats of {} bytes "
                "need {} bytes, but only {} remain (truncated file or wrong counts)",
                sec.partial_buckets, sec.bucket_count, bucket_storage, sec.max_splats,
                sec.bytes_per_splat, partial_bytes + bucket_bytes + splat_bytes, remaining));
        }
        sec.partial_offset = offset;
        sec.centres_offset = offset + partial_bytes;
        sec.data_offset = offset + partial_bytes + bucket_bytes;
        offset = sec.data_offset + splat_bytes;
        if (mode_index > 0 && sec.splats > 0) {
            if (sec.bucket_count > 0 && bucket_storage < kBucketCentreBytes) {
                fail(fmt::format("bucket storage of {} bytes cannot hold a bucket centre",
                                 bucket_storage));
            }
            if (sec.full_buckets + sec.partial_buckets > sec.bucket_count) {
                fail(fmt::format("{} full and {} partially filled buckets, but bucketCount is {}",
                                 sec.full_buckets, sec.partial_buckets, sec.bucket_count));
            }
            if (!std::isfinite(block_size)) {
                fail(fmt::format("bucket block size {} is not finite", block_size));
            }
            sec.position_scale = double(block_size) / 2.0 / sec.range;
        }
        sec.first = total;
        total += static_cast<int64_t>(sec.splats);
        if (sec.splats > 0) degree = std::max(degree, sec.degree);
    }
    if (static_cast<uint64_t>(total) != header_splats) {
        core::ThrowError(
            "'{}': main header: splatCount {} but the sections hold {} splats (truncated or "
            "inconsistent file)",
            filename, header_splats, total);
    }

    // Bucket of every splat (modes 1-2), checked before decoding.
    std::vector<uint32_t> bucket_of;
    if (mode_index > 0) bucket_of.resize(total);
    for (uint64_t s = 0; s < max_sections && mode_index > 0; ++s) {
        const Section& sec = sections[s];
        const uint64_t in_full = sec.full_buckets * sec.bucket_size;
        uint64_t bucket = sec.full_buckets, bucket_start = in_full, partial = 0;
        uint64_t bucket_length = 0;
        if (sec.partial_buckets > 0) bucket_length = Load<uint32_t>(bytes + sec.partial_offset);
        for (uint64_t j = 0; j < sec.splats; ++j) {
            if (j < in_full) {
                bucket_of[sec.first + j] = static_cast<uint32_t>(j / sec.bucket_size);
                continue;
            }
            while (partial < sec.partial_buckets && j >= bucket_start + bucket_length) {
                bucket_start += bucket_length;
                ++bucket;
                if (++partial < sec.partial_buckets) {
                    bucket_length = Load<uint32_t>(bytes + sec.partial_offset + partial * 4);
                }
            }
            if (partial >= sec.partial_buckets) {
                core::ThrowError(
                    "'{}': section {}: splat {} lies beyond its {} full buckets of {} and {} "
                    "partially filled buckets",
                    filename, s, j, sec.full_buckets, sec.bucket_size, sec.partial_buckets);
            }
            bucket_of[sec.first + j] = static_cast<uint32_t>(bucket);
        }
    }

    SplatColumns columns;
    columns.Allocate(filename, total, /*gaussian=*/true, degree);
    float* positions = columns.positions.Data<float>();
    float* scale = columns.scale.Data<float>();
    float* rot = columns.rot.Data<float>();
    float* opacity = columns.opacity.Data<float>();
    float* f_dc = columns.f_dc.Data<float>();
    const int nc = NumSHRestCoeffs(degree);
    float* f_rest = nc > 0 ? columns.f_rest.Data<float>() : nullptr;
    if (f_rest != nullptr) std::fill(f_rest, f_rest + total * nc * 3, 0.0f);

    auto value = [&](const uint8_t* p, int width) -> double {  // one f32 or f16 value
        return width == 4 ? double(Load<float>(p)) : double(HalfToFloat(Load<uint16_t>(p)));
    };
    for (const Section& sec : sections) {
        const int sec_nc = NumSHRestCoeffs(sec.degree);
        const int scale_at = 3 * mode.centre_bytes;
        const int rotation_at = scale_at + 3 * mode.scale_bytes;
        const int colour_at = rotation_at + 4 * mode.rotation_bytes;
        const int sh_at = colour_at + 4;
        core::ParallelFor(
            static_cast<int64_t>(sec.splats),
            [&](int64_t j) {
                const int64_t i = sec.first + j;
                const uint8_t* record = bytes + sec.data_offset + j * sec.bytes_per_splat;
                for (int c = 0; c < 3; ++c) {
                    if (mode_index == 0) {
                        positions[i * 3 + c] = Load<float>(record + 4 * c);
                    } else {
                        const float centre = Load<float>(bytes + sec.centres_offset +
                                                         bucket_of[i] * kBucketCentreBytes + 4 * c);
                        const double u = Load<uint16_t>(record + 2 * c);
                        positions[i * 3 + c] =
                            static_cast<float>((u - sec.range) * sec.position_scale + centre);
                    }
                    scale[i * 3 + c] = static_cast<float>(std::abs(
                        value(record + scale_at + mode.scale_bytes * c, mode.scale_bytes)));
                    f_dc[i * 3 + c] =
                        static_cast<float>((record[colour_at + c] / 255.0 - 0.5) / kSH_C0);
                }
                for (int c = 0; c < 4; ++c) {
                    rot[i * 4 + c] = static_cast<float>(
                        value(record + rotation_at + mode.rotation_bytes * c, mode.rotation_bytes));
                }
                const double alpha =
                    std::clamp(record[colour_at + 3] / 255.0, kAlphaMargin, 1.0 - kAlphaMargin);
                opacity[i] = static_cast<float>(std::log(alpha / (1.0 - alpha)));
                for (int k = 0; k < sec_nc; ++k) {
                    for (int ch = 0; ch < 3; ++ch) {
                        const uint8_t* p = record + sh_at + RecordSHIndex(k, ch) * mode.sh_bytes;
                        const double v = mode.sh_bytes == 1
                                             ? *p / 255.0 * (double(sh_max) - sh_min) + sh_min
                                             : value(p, mode.sh_bytes);
                        f_rest[(i * nc + k) * 3 + ch] = static_cast<float>(v);
                    }
                }
            },
            4096);
    }

    report.trailing_bytes = static_cast<int64_t>(size - offset);
    if (report.trailing_bytes > 0) {
        core::LogWarning("'{}': ignoring {} bytes after the last section", filename,
                         report.trailing_bytes);
    }
    return FinalizeColumns(filename, columns, options, report);
}

}  // namespace io
}  // namespace t
}  // namespace open3d
