// PlayCanvas compressed PLY: reader and writer.
//
// There is no formal specification. What this file relies on, and where it comes from:
//   - playcanvas/engine src/scene/gsplat/gsplat-compressed-data.js (the engine's reader),
//   - playcanvas/splat-transform src/lib/readers/decompress-ply.ts (the reader paired with
//     the writer) and src/lib/writers/write-compressed-ply.ts + compressed-chunk.ts (writer),
//     src/lib/data-table/morton-order.ts (the writer's splat order),
//   - the blog post https://blog.playcanvas.com/compressing-gaussian-splats/ .
//
// Layout: binary_little_endian PLY with, in this order,
//   element chunk   ceil(N / 256) rows of float32: min_x min_y min_z max_x max_y max_z
//                   min_scale_x min_scale_y min_scale_z max_scale_x max_scale_y max_scale_z
//                   [min_r min_g min_b max_r max_g max_b]. Scale bounds are LOG scales; the
//                   colour bounds are in colour space (0.5 + SH_C0 * f_dc), and older files
//                   have no colour bounds (12 properties): their colour bytes are the colour.
//   element vertex  N rows of uint32: packed_position, packed_rotation, packed_scale,
//                   packed_color. Splat i belongs to chunk floor(i / 256).
//   element sh      optional, N rows of uchar f_rest_0 .. f_rest_{K-1}, K = 9, 24 or 45, in
//                   the 3DGS PLY order (channel-major: f_rest_[c * Nc + k]).
// Bit layouts (unorm(v, b) = (v & (2^b - 1)) / (2^b - 1), lerp(a, b, t) = a (1 - t) + b t):
//   position / scale  x: bits 21-31 (11 bits), y: bits 11-20 (10), z: bits 0-10 (11); the
//                     value is lerp(chunk min, chunk max, unorm).
//   color             r: bits 24-31, g: 16-23, b: 8-15, alpha: 0-7 (8 bits each); colour =
//                     lerp(min_c, max_c, unorm) when the chunk has colour bounds; f_dc =
//                     (colour - 0.5) / SH_C0; alpha = unorm is sigmoid(opacity).
//   rotation          bits 30-31: index L of the largest |component| of (rot_0, rot_1, rot_2,
//                     rot_3) = (w, x, y, z) after making it positive; bits 20-29, 10-19, 0-9:
//                     the other three components in index order, each (unorm - 0.5) * sqrt(2);
//                     component L = sqrt(1 - (a^2 + b^2 + c^2)).
//   sh                v = ((byte + 0.5) / 256 - 0.5) * 8, except byte 0 -> -4, 255 -> +4
//                     (decompress-ply.ts; the writer stores trunc((v / 8 + 0.5) * 256)
//                     clamped to 0..255, so this is the centre of the byte's bin). The engine's
//                     byte * 8 / 255 - 4 differs by at most 1/64 of a unit; we follow the
//                     reader that belongs to the writer.
//   Axes are those of the 3DGS PLY (splat-transform converts to its PLY space before
//   writing); nothing is flipped.
//
// Reading: every value is computed as the references do (double arithmetic, rounded to
// float32 once); log-scales are rounded to float32 and then exponentiated as the PLY reader
// does. Alpha 0 and 255 give opacity -40 and +40 (the engine's choice; decompress-ply.ts
// gives -inf/+inf, which FinalizeColumns would refuse). Properties are found by name and
// other elements or properties are skipped, but each element must have fixed-size rows; the
// chunk count must be ceil(N / 256), the sh count N.
//
// Writing: the splat-transform layout (18 chunk floats, comment line, `sh` element when the
// cloud has SH), with these decisions:
//   - Order: splats are written in splat-transform's Morton order (10 bits per axis over the
//     bounding box, stable sort, runs of more than 256 equal codes re-sorted within their own
//     box), which keeps the chunks' boxes small and so the position quantum small; but when
//     the input order is already as coherent (its chunks' summed quanta at most 1.25 times
//     those of the Morton order: files we wrote and read back, inputs already sorted), the
//     input order is kept. Reading therefore may return the splats in another order than the
//     cloud that was written. The reader does not depend on any order.
//   - Quantisation: as compressed-chunk.ts. Chunk bounds are the float minimum and maximum
//     of the chunk's positions, log-scales (EncodeLogScale, clamped to [-20, 20]) and colours
//     (0.5 + SH_C0 f_dc); each splat is normalised to them and rounded to nearest, except
//     that a chunk range below 1e-5 is still normalised (the reference stores 0 there), and
//     that a code next to the rounded one is used when only it decodes to exactly the input
//     value, and likewise another rotation index when the largest components nearly tie.
//     So a cloud read from a compressed PLY is written back code for code: the splats at
//     the ends of a range decode to the bounds themselves, and encoding the decoded values
//     gives the same bounds (tested, also on values where decoding is many-to-one), so
//     write -> read -> write reproduces the file and the values.
//   - Non-finite values, negative scales and zero quaternions are refused with the splat's
//     index: the format cannot hold them.
//
// Quantisation bounds of a write -> read round trip (q = chunk range / (2^bits - 1)):
//   position: |error| <= q / 2 (11, 10, 11 bits for x, y, z) plus float rounding;
//   log-scale: the same with the log-scale clamped to [-20, 20];
//   colour (0.5 + SH_C0 f_dc): |error| <= (max - min) / 255 / 2;
//   alpha = sigmoid(opacity): |error| <= 0.5 / 255;
//   rotation (sign chosen so the largest component is positive): the three stored components
//   within sqrt(2) / 1023 / 2, the largest within 3 times that;
//   f_rest: within 1/64 for values in [-4 + 1/32, 4 - 1/32), else of the value clamped to
//   [-4, 4] within 1/32.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <numeric>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/PlyHeader.h"
#include "open3d/t/io/SplatColumns.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using geometry::kSH_C0;
using geometry::NumSHRestCoeffs;

constexpr int64_t kChunkSplats = 256;
constexpr int kChunkFloats = 18;
constexpr double kLogScaleClamp = 20.0;
constexpr double kOpacityAtAlpha0 = -40.0;  // the engine's values for alpha 0 and 255
constexpr double kOpacityAtAlpha255 = 40.0;
// sqrt(2) computed as the references write it, so that the rotation codes agree bit for bit.
const double kRotDecodeNorm = 1.0 / (std::sqrt(2.0) * 0.5);
const double kRotEncodeNorm = std::sqrt(2.0) * 0.5;
// Morton order is replaced by the input order when that is at most this much worse.
constexpr double kKeepInputOrderRatio = 1.25;

const char* const kChunkNames[kChunkFloats] = {
    "min_x",       "min_y",       "min_z",       "max_x",       "max_y",       "max_z",
    "min_scale_x", "min_scale_y", "min_scale_z", "max_scale_x", "max_scale_y", "max_scale_z",
    "min_r",       "min_g",       "min_b",       "max_r",       "max_g",       "max_b"};
const char* const kVertexNames[4] = {"packed_position", "packed_rotation", "packed_scale",
                                     "packed_color"};

// ---------------------------------------------------------------------------------------
// Decoding, shared by the reader and by the writer's exact-value check.

double Unorm(uint32_t value, int bits) {
    const uint32_t top = (1u << bits) - 1;
    return static_cast<double>(value & top) / top;
}

double Lerp(double a, double b, double t) { return a * (1.0 - t) + b * t; }

// Fields x, y, z of an 11/10/11 word: their shifts and widths.
constexpr int kShift111011[3] = {21, 11, 0};
constexpr int kBits111011[3] = {11, 10, 11};

float DecodeLinear(float lo, float hi, uint32_t code, int bits) {
    return static_cast<float>(Lerp(lo, hi, Unorm(code, bits)));
}

float DecodeScale(float lo, float hi, uint32_t code, int bits) {
    return DecodeLogScale(DecodeLinear(lo, hi, code, bits));
}

float ColourToFDc(double colour) { return static_cast<float>((colour - 0.5) / kSH_C0); }

float DecodeColour(bool bounds, float lo, float hi, uint32_t code) {
    const double t = Unorm(code, 8);
    return ColourToFDc(bounds ? Lerp(lo, hi, t) : t);
}

float DecodeOpacity(uint32_t code) {
    const double alpha = Unorm(code, 8);
    if (alpha <= 0.0) return static_cast<float>(kOpacityAtAlpha0);
    if (alpha >= 1.0) return static_cast<float>(kOpacityAtAlpha255);
    return static_cast<float>(-std::log(1.0 / alpha - 1.0));
}

// (w, x, y, z) as the reader hands it out, FinalizeColumns' normalisation included.
void DecodeRotation(uint32_t word, float out[4]) {
    const double stored[3] = {(Unorm(word >> 20, 10) - 0.5) * kRotDecodeNorm,
                              (Unorm(word >> 10, 10) - 0.5) * kRotDecodeNorm,
                              (Unorm(word, 10) - 0.5) * kRotDecodeNorm};
    const double sum = stored[0] * stored[0] + stored[1] * stored[1] + stored[2] * stored[2];
    const double largest = std::sqrt(std::max(0.0, 1.0 - sum));
    const uint32_t index = word >> 30;
    for (uint32_t k = 0, j = 0; k < 4; ++k) {
        out[k] = static_cast<float>(k == index ? largest : stored[j++]);
    }
    const double n2 = double(out[0]) * out[0] + double(out[1]) * out[1] + double(out[2]) * out[2] +
                      double(out[3]) * out[3];
    if (n2 > 0.0 && std::abs(n2 - 1.0) > 0x1p-20) {  // as FinalizeColumns does
        const double inv = 1.0 / std::sqrt(n2);
        for (int k = 0; k < 4; ++k) out[k] = static_cast<float>(out[k] * inv);
    }
}

float DecodeSH(uint8_t byte) {
    const double unit = byte == 0 ? 0.0 : byte == 255 ? 1.0 : (byte + 0.5) / 256.0;
    return static_cast<float>((unit - 0.5) * 8.0);
}

// ---------------------------------------------------------------------------------------
// Reader.

const char* PlyTypeName(PlyType type) {  // in PlyType's order
    static const char* const kNames[] = {"char", "uchar", "short", "ushort",
                                         "int",  "uint",  "float", "double"};
    return kNames[static_cast<int>(type)];
}

// Byte offset of a required scalar property of the given type inside the element's row.
int64_t RequireProperty(const std::string& filename, const PlyElement& element,
                        const std::string& name, PlyType type) {
    const int index = element.FindProperty(name);
    if (index < 0) {
        core::ThrowError("'{}': missing required property '{}' in element '{}' (compressed PLY)",
                         filename, name, element.name);
    }
    const PlyProperty& p = element.properties[index];
    if (p.type != type) {
        core::ThrowError(
            "'{}': property '{}' of element '{}' is {}; compressed PLY stores it as {}", filename,
            name, element.name, PlyTypeName(p.type), PlyTypeName(type));
    }
    return p.offset;
}

template <typename T>
T LoadLE(const uint8_t* p) {  // the file is little endian, as is every host we build for
    T value;
    std::memcpy(&value, p, sizeof(T));
    return value;
}

}  // namespace

geometry::PointCloud ReadCompressedPly(const std::string& filename,
                                       const ReadPointCloudOptions& options,
                                       ReadPointCloudReport& report) {
    const MappedFile bytes(filename);
    const PlyHeader header = ParsePlyHeader(filename, bytes.data(), bytes.size());
    if (header.encoding != PlyEncoding::BinaryLittleEndian) {
        core::ThrowError("'{}': compressed PLY must be binary_little_endian, this file is {}",
                         filename,
                         header.encoding == PlyEncoding::Ascii ? "ascii" : "binary_big_endian");
    }

    // Each element's rows follow the previous element's; all must be fixed-size and fit.
    const uint64_t size = bytes.size();
    uint64_t offset = header.data_offset;
    const PlyElement *chunk = nullptr, *vertex = nullptr, *sh = nullptr;
    uint64_t chunk_offset = 0, vertex_offset = 0, sh_offset = 0;
    for (const PlyElement& e : header.elements) {
        if (e.HasList()) {
            core::ThrowError(
                "'{}': element '{}' has a list property; compressed PLY elements have "
                "fixed-size rows",
                filename, e.name);
        }
        const uint64_t row = static_cast<uint64_t>(e.RowSize());
        const uint64_t remaining = size - offset;
        if (row > 0 && static_cast<uint64_t>(e.count) > remaining / row) {
            core::ThrowError(
                "'{}': element '{}' declares {} rows of {} bytes but only {} bytes remain: the "
                "file is truncated or the count is wrong",
                filename, e.name, e.count, row, remaining);
        }
        auto locate = [&](const char* name, const PlyElement*& found, uint64_t& found_offset) {
            if (e.name != name) return;
            if (found != nullptr) {
                core::ThrowError("'{}': element '{}' appears twice", filename, e.name);
            }
            found = &e;
            found_offset = offset;
        };
        locate("chunk", chunk, chunk_offset);
        locate("vertex", vertex, vertex_offset);
        locate("sh", sh, sh_offset);
        offset += static_cast<uint64_t>(e.count) * row;
    }
    if (chunk == nullptr) {
        core::ThrowError("'{}': compressed PLY has no 'chunk' element", filename);
    }
    if (vertex == nullptr) {
        core::ThrowError("'{}': compressed PLY has no 'vertex' element", filename);
    }

    // Chunk bounds: 12 required, the 6 colour bounds all or none.
    int64_t chunk_props[kChunkFloats];
    for (int k = 0; k < 12; ++k) {
        chunk_props[k] = RequireProperty(filename, *chunk, kChunkNames[k], PlyType::Float32);
    }
    int num_colour = 0;
    for (int k = 12; k < kChunkFloats; ++k) num_colour += chunk->FindProperty(kChunkNames[k]) >= 0;
    const bool colour_bounds = num_colour > 0;
    if (colour_bounds) {
        for (int k = 12; k < kChunkFloats; ++k) {
            if (chunk->FindProperty(kChunkNames[k]) < 0) {
                core::ThrowError(
                    "'{}': element 'chunk' has {} of the 6 colour bounds but not '{}' (all of "
                    "min_r .. max_b or none)",
                    filename, num_colour, kChunkNames[k]);
            }
            chunk_props[k] = RequireProperty(filename, *chunk, kChunkNames[k], PlyType::Float32);
        }
    }
    int64_t vertex_props[4];
    for (int k = 0; k < 4; ++k) {
        vertex_props[k] = RequireProperty(filename, *vertex, kVertexNames[k], PlyType::UInt32);
    }

    const int64_t n = vertex->count;
    const int64_t num_chunks = (n + kChunkSplats - 1) / kChunkSplats;
    if (chunk->count != num_chunks) {
        core::ThrowError(
            "'{}': element 'chunk' has {} rows; {} vertices need ceil({} / 256) = {} chunks",
            filename, chunk->count, n, n, num_chunks);
    }

    int degree = 0;
    std::vector<int64_t> sh_props;
    if (sh != nullptr) {
        int num_rest = 0;
        while (sh->FindProperty("f_rest_" + std::to_string(num_rest)) >= 0) ++num_rest;
        for (const PlyProperty& p : sh->properties) {
            if (p.name.rfind("f_rest_", 0) != 0) continue;
            int k = -1;
            const char* end = p.name.data() + p.name.size();
            const auto [ptr, ec] = std::from_chars(p.name.data() + 7, end, k);
            if (ec == std::errc() && ptr == end && k >= num_rest) {
                core::ThrowError(
                    "'{}': element 'sh': f_rest properties are not contiguous ('{}' present, "
                    "'f_rest_{}' missing)",
                    filename, p.name, num_rest);
            }
        }
        degree = -1;
        for (int d = 1; d <= 3; ++d) {
            if (num_rest == 3 * NumSHRestCoeffs(d)) degree = d;
        }
        if (degree < 0) {
            core::ThrowError(
                "'{}': element 'sh' has {} f_rest properties; expected 9, 24 or 45 (SH degree "
                "1, 2 or 3)",
                filename, num_rest);
        }
        for (int k = 0; k < num_rest; ++k) {
            sh_props.push_back(
                RequireProperty(filename, *sh, "f_rest_" + std::to_string(k), PlyType::UInt8));
        }
        if (sh->count != n) {
            core::ThrowError("'{}': element 'sh' has {} rows but element 'vertex' has {}", filename,
                             sh->count, n);
        }
    }

    // The chunk table, 18 floats per chunk (the colour bounds unused without them).
    std::vector<float> bounds(num_chunks * kChunkFloats, 0.0f);
    const int64_t chunk_row = chunk->RowSize();
    for (int64_t c = 0; c < num_chunks; ++c) {
        const uint8_t* row = bytes.data() + chunk_offset + c * chunk_row;
        for (int k = 0; k < (colour_bounds ? kChunkFloats : 12); ++k) {
            bounds[c * kChunkFloats + k] = LoadLE<float>(row + chunk_props[k]);
        }
    }

    SplatColumns columns;
    columns.Allocate(n, /*gaussian=*/true, degree);
    float* positions = columns.positions.Data<float>();
    float* scale = columns.scale.Data<float>();
    float* rot = columns.rot.Data<float>();
    float* opacity = columns.opacity.Data<float>();
    float* f_dc = columns.f_dc.Data<float>();
    const int nc = NumSHRestCoeffs(degree);
    float* f_rest = nc > 0 ? columns.f_rest.Data<float>() : nullptr;
    const int64_t vertex_row = vertex->RowSize();
    const int64_t sh_row = sh != nullptr ? sh->RowSize() : 0;
    core::ParallelFor(
        n,
        [&](int64_t i) {
            const float* b = bounds.data() + (i / kChunkSplats) * kChunkFloats;
            const uint8_t* row = bytes.data() + vertex_offset + i * vertex_row;
            const uint32_t packed_position = LoadLE<uint32_t>(row + vertex_props[0]);
            const uint32_t packed_rotation = LoadLE<uint32_t>(row + vertex_props[1]);
            const uint32_t packed_scale = LoadLE<uint32_t>(row + vertex_props[2]);
            const uint32_t packed_color = LoadLE<uint32_t>(row + vertex_props[3]);
            for (int f = 0; f < 3; ++f) {
                const int shift = kShift111011[f], bits = kBits111011[f];
                positions[i * 3 + f] = DecodeLinear(b[f], b[3 + f], packed_position >> shift, bits);
                scale[i * 3 + f] = DecodeScale(b[6 + f], b[9 + f], packed_scale >> shift, bits);
                f_dc[i * 3 + f] =
                    DecodeColour(colour_bounds, b[12 + f], b[15 + f], packed_color >> (24 - 8 * f));
            }
            opacity[i] = DecodeOpacity(packed_color);
            DecodeRotation(packed_rotation, rot + i * 4);
            if (f_rest != nullptr) {
                const uint8_t* sh_bytes = bytes.data() + sh_offset + i * sh_row;
                for (int c = 0; c < 3; ++c) {
                    for (int k = 0; k < nc; ++k) {
                        f_rest[(i * nc + k) * 3 + c] = DecodeSH(sh_bytes[sh_props[c * nc + k]]);
                    }
                }
            }
        },
        2048);

    report.trailing_bytes = static_cast<int64_t>(size - offset);
    if (report.trailing_bytes > 0) {
        core::LogWarning("'{}': ignoring {} bytes after the declared elements", filename,
                         report.trailing_bytes);
    }
    return FinalizeColumns(filename, columns, options, report);
}

namespace {

// ---------------------------------------------------------------------------------------
// Writer.

uint32_t PackUnorm(double value, int bits) {  // compressed-chunk.ts packUnorm
    const double top = (1u << bits) - 1;
    return static_cast<uint32_t>(std::clamp(std::floor(value * top + 0.5), 0.0, top));
}

double Normalise(double x, double lo, double hi) {
    if (x <= lo) return 0.0;
    if (x >= hi) return 1.0;
    return (x - lo) / (hi - lo);
}

// The code nearest to x in [lo, hi]; a neighbour instead when only it decodes to `target`.
template <typename Decode>
uint32_t Quantise(double x, double lo, double hi, int bits, float target, Decode decode) {
    const uint32_t code = PackUnorm(Normalise(x, lo, hi), bits);
    if (decode(code) == target) return code;
    const uint32_t top = (1u << bits) - 1;
    if (code > 0 && decode(code - 1) == target) return code - 1;
    if (code < top && decode(code + 1) == target) return code + 1;
    return code;
}

// compressed-chunk.ts packRot: normalise, largest |component| positive, three 10-bit values.
uint32_t PackRotationReference(const float rot[4]) {
    double q[4];
    const double length = std::sqrt(double(rot[0]) * rot[0] + double(rot[1]) * rot[1] +
                                    double(rot[2]) * rot[2] + double(rot[3]) * rot[3]);
    const double inv = 1.0 / length;
    for (int k = 0; k < 4; ++k) q[k] = rot[k] * inv;
    int largest = 0;
    for (int k = 1; k < 4; ++k) {
        if (std::abs(q[k]) > std::abs(q[largest])) largest = k;
    }
    if (q[largest] < 0) {
        for (double& v : q) v = -v;
    }
    uint32_t word = static_cast<uint32_t>(largest);
    for (int k = 0; k < 4; ++k) {
        if (k != largest) word = (word << 10) | PackUnorm(q[k] * kRotEncodeNorm + 0.5, 10);
    }
    return word;
}

bool SameRotation(uint32_t word, const float rot[4]) {
    float decoded[4];
    DecodeRotation(word, decoded);
    return decoded[0] == rot[0] && decoded[1] == rot[1] && decoded[2] == rot[2] &&
           decoded[3] == rot[3];
}

// The reference code, or one that decodes to exactly `rot` when such a code exists (a near
// tie for the largest component can make the reference choose another index than the one
// the value was decoded from).
uint32_t PackRotation(const float rot[4]) {
    const uint32_t reference = PackRotationReference(rot);
    if (SameRotation(reference, rot)) return reference;
    float max_abs = 0.0f;
    for (int k = 0; k < 4; ++k) max_abs = std::max(max_abs, std::abs(rot[k]));
    for (uint32_t largest = 0; largest < 4; ++largest) {
        if (rot[largest] < 0.0f || rot[largest] < max_abs - 0.01f) continue;
        uint32_t word = largest;
        for (uint32_t k = 0; k < 4; ++k) {
            if (k != largest) word = (word << 10) | PackUnorm(rot[k] * kRotEncodeNorm + 0.5, 10);
        }
        if (SameRotation(word, rot)) return word;
    }
    return reference;
}

uint8_t QuantiseSH(float v) {  // write-compressed-ply.ts
    const double unit = double(v) / 8.0 + 0.5;
    return static_cast<uint8_t>(std::clamp(std::trunc(unit * 256.0), 0.0, 255.0));
}

// https://fgiesen.wordpress.com/2009/12/13/decoding-morton-codes/ (as morton-order.ts).
uint32_t Part1By2(uint32_t x) {
    x &= 0x000003ff;
    x = (x ^ (x << 16)) & 0xff0000ff;
    x = (x ^ (x << 8)) & 0x0300f00f;
    x = (x ^ (x << 4)) & 0x030c30c3;
    x = (x ^ (x << 2)) & 0x09249249;
    return x;
}

// morton-order.ts sortMortonOrder on order[begin, end).
void SortMorton(const float* positions, std::vector<uint32_t>& order, size_t begin, size_t end) {
    if (begin >= end) return;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = begin; i < end; ++i) {
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], double(positions[size_t(order[i]) * 3 + a]));
            hi[a] = std::max(hi[a], double(positions[size_t(order[i]) * 3 + a]));
        }
    }
    double mul[3];
    bool all_zero = true;
    for (int a = 0; a < 3; ++a) {
        const double length = hi[a] - lo[a];
        if (!std::isfinite(length)) return;
        all_zero = all_zero && length == 0.0;
        mul[a] = length == 0.0 ? 0.0 : 1024.0 / length;
    }
    if (all_zero) return;
    std::vector<std::pair<uint32_t, uint32_t>> keyed(end - begin);  // (code, splat)
    for (size_t i = begin; i < end; ++i) {
        uint32_t cell[3];
        for (int a = 0; a < 3; ++a) {
            const double v = (double(positions[size_t(order[i]) * 3 + a]) - lo[a]) * mul[a];
            cell[a] = static_cast<uint32_t>(std::min(1023.0, v));
        }
        keyed[i - begin] = {(Part1By2(cell[2]) << 2) + (Part1By2(cell[1]) << 1) + Part1By2(cell[0]),
                            order[i]};
    }
    std::stable_sort(keyed.begin(), keyed.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    for (size_t i = begin; i < end; ++i) order[i] = keyed[i - begin].second;
    for (size_t start = 0; start < keyed.size();) {
        size_t stop = start + 1;
        while (stop < keyed.size() && keyed[stop].first == keyed[start].first) ++stop;
        if (stop - start > static_cast<size_t>(kChunkSplats)) {
            SortMorton(positions, order, begin + start, begin + stop);
        }
        start = stop;
    }
}

// Summed position quanta of the chunks an order makes (smaller is finer quantisation).
double ChunkCost(const float* positions, const std::vector<uint32_t>& order) {
    double cost = 0.0;
    for (size_t start = 0; start < order.size(); start += kChunkSplats) {
        const size_t stop = std::min(order.size(), start + kChunkSplats);
        for (int a = 0; a < 3; ++a) {
            double lo = INFINITY, hi = -INFINITY;
            for (size_t i = start; i < stop; ++i) {
                lo = std::min(lo, double(positions[size_t(order[i]) * 3 + a]));
                hi = std::max(hi, double(positions[size_t(order[i]) * 3 + a]));
            }
            cost += (hi - lo) / ((1 << kBits111011[a]) - 1);
        }
    }
    return cost;
}

void CheckWritable(const std::string& filename, const geometry::GaussianSplatArrays& a) {
    const int nc = a.num_rest;
    for (int64_t i = 0; i < a.num_points; ++i) {
        auto fail = [&](const char* what, double value) {
            core::ThrowError(
                "Cannot write '{}': splat {} has {} {}, which compressed PLY cannot store",
                filename, i, what, value);
        };
        for (int c = 0; c < 3; ++c) {
            if (!std::isfinite(a.positions[i * 3 + c]))
                fail("a non-finite position", a.positions[i * 3 + c]);
            if (!(a.scale[i * 3 + c] >= 0.0f) || std::isinf(a.scale[i * 3 + c]))
                fail("a negative or non-finite scale", a.scale[i * 3 + c]);
            if (!std::isfinite(a.f_dc[i * 3 + c])) fail("a non-finite f_dc", a.f_dc[i * 3 + c]);
        }
        if (std::isnan(a.opacity[i])) fail("opacity", a.opacity[i]);
        double n2 = 0.0;
        for (int c = 0; c < 4; ++c) {
            const float q = a.rot[i * 4 + c];
            if (!std::isfinite(q)) fail("a non-finite rotation component", q);
            n2 += double(q) * q;
        }
        if (n2 == 0.0) fail("a zero rotation quaternion, norm", 0.0);
        for (int k = 0; k < nc * 3; ++k) {
            if (std::isnan(a.f_rest[i * nc * 3 + k])) fail("f_rest", a.f_rest[i * nc * 3 + k]);
        }
    }
}

}  // namespace

void WriteCompressedPly(const std::string& filename, const geometry::PointCloud& cloud) {
    if (!cloud.IsGaussianSplat()) {
        core::ThrowError(
            "Cannot write '{}': compressed PLY needs a Gaussian splat cloud (scale, rot, "
            "opacity, f_dc)",
            filename);
    }
    const geometry::GaussianSplatArrays a = cloud.GetGaussianSplatArrays();
    CheckWritable(filename, a);
    const int64_t n = a.num_points;
    if (n > int64_t(UINT32_MAX)) {
        core::ThrowError("Cannot write '{}': {} splats; compressed PLY holds at most 2^32 - 1",
                         filename, n);
    }
    const int nc = a.num_rest;
    const int64_t num_chunks = (n + kChunkSplats - 1) / kChunkSplats;

    // Splat order (see the top of the file).
    std::vector<uint32_t> input_order(n), order(n);
    std::iota(input_order.begin(), input_order.end(), 0u);
    order = input_order;
    SortMorton(a.positions, order, 0, order.size());
    const double input_cost = ChunkCost(a.positions, input_order);
    const double morton_cost = ChunkCost(a.positions, order);
    if (input_cost <= kKeepInputOrderRatio * morton_cost) {
        order.swap(input_order);
        core::LogDebug("'{}': input order kept (chunk cost {} vs Morton order {})", filename,
                       input_cost, morton_cost);
    }

    std::vector<float> log_scales(n * 3);
    core::ParallelFor(
        n * 3, [&](int64_t k) { log_scales[k] = EncodeLogScale(a.scale[k]); }, 8192);

    std::vector<float> chunk_data(num_chunks * kChunkFloats);
    std::vector<uint32_t> vertex_data(n * 4);
    std::vector<uint8_t> sh_data(n * nc * 3);
    core::ParallelFor(
        num_chunks,
        [&](int64_t c) {
            const int64_t begin = c * kChunkSplats, end = std::min(n, begin + kChunkSplats);
            float* b = chunk_data.data() + c * kChunkFloats;
            for (int f = 0; f < 3; ++f) {
                float lo = INFINITY, hi = -INFINITY, slo = INFINITY, shi = -INFINITY;
                double clo = INFINITY, chi = -INFINITY;
                for (int64_t j = begin; j < end; ++j) {
                    const int64_t i = order[j];
                    lo = std::min(lo, a.positions[i * 3 + f]);
                    hi = std::max(hi, a.positions[i * 3 + f]);
                    slo = std::min(slo, log_scales[i * 3 + f]);
                    shi = std::max(shi, log_scales[i * 3 + f]);
                    const double colour = double(a.f_dc[i * 3 + f]) * kSH_C0 + 0.5;
                    clo = std::min(clo, colour);
                    chi = std::max(chi, colour);
                }
                b[f] = lo;
                b[3 + f] = hi;
                b[6 + f] = std::clamp(slo, float(-kLogScaleClamp), float(kLogScaleClamp));
                b[9 + f] = std::clamp(shi, float(-kLogScaleClamp), float(kLogScaleClamp));
                b[12 + f] = static_cast<float>(clo);
                b[15 + f] = static_cast<float>(chi);
            }
            for (int64_t j = begin; j < end; ++j) {
                const int64_t i = order[j];
                uint32_t position = 0, scale = 0, colour = 0;
                for (int f = 0; f < 3; ++f) {
                    const int shift = kShift111011[f], bits = kBits111011[f];
                    const float lo = b[f], hi = b[3 + f], slo = b[6 + f], shi = b[9 + f];
                    const float clo = b[12 + f], chi = b[15 + f];
                    position |=
                        Quantise(a.positions[i * 3 + f], lo, hi, bits, a.positions[i * 3 + f],
                                 [&](uint32_t q) { return DecodeLinear(lo, hi, q, bits); })
                        << shift;
                    scale |= Quantise(log_scales[i * 3 + f], slo, shi, bits, a.scale[i * 3 + f],
                                      [&](uint32_t q) { return DecodeScale(slo, shi, q, bits); })
                             << shift;
                    colour |= Quantise(double(a.f_dc[i * 3 + f]) * kSH_C0 + 0.5, clo, chi, 8,
                                       a.f_dc[i * 3 + f],
                                       [&](uint32_t q) { return DecodeColour(true, clo, chi, q); })
                              << (24 - 8 * f);
                }
                const double alpha = 1.0 / (1.0 + std::exp(-double(a.opacity[i])));
                colour |= Quantise(alpha, 0.0, 1.0, 8, a.opacity[i], DecodeOpacity);
                uint32_t* out = vertex_data.data() + j * 4;
                out[0] = position;
                out[1] = PackRotation(a.rot + i * 4);
                out[2] = scale;
                out[3] = colour;
                // sh: file order f_rest_[ch * Nc + k]; ours [Nc, 3].
                for (int ch = 0; ch < 3; ++ch) {
                    for (int k = 0; k < nc; ++k) {
                        sh_data[(j * 3 + ch) * nc + k] =
                            QuantiseSH(a.f_rest[(i * nc + k) * 3 + ch]);
                    }
                }
            }
        },
        1);

    std::string header =
        "ply\nformat binary_little_endian 1.0\ncomment Generated by Open3D (PlayCanvas "
        "compressed PLY)\n";
    header += fmt::format("element chunk {}\n", num_chunks);
    for (const char* name : kChunkNames) header += fmt::format("property float {}\n", name);
    header += fmt::format("element vertex {}\n", n);
    for (const char* name : kVertexNames) header += fmt::format("property uint {}\n", name);
    if (nc > 0) {
        header += fmt::format("element sh {}\n", n);
        for (int k = 0; k < nc * 3; ++k) header += fmt::format("property uchar f_rest_{}\n", k);
    }
    header += "end_header\n";

    std::vector<uint8_t> bytes(header.begin(), header.end());
    auto append = [&](const void* data, size_t count) {
        const auto* p = static_cast<const uint8_t*>(data);
        bytes.insert(bytes.end(), p, p + count);
    };
    append(chunk_data.data(), chunk_data.size() * sizeof(float));
    append(vertex_data.data(), vertex_data.size() * sizeof(uint32_t));
    append(sh_data.data(), sh_data.size());
    WriteFileBytes(filename, bytes);
}

}  // namespace io
}  // namespace t
}  // namespace open3d
