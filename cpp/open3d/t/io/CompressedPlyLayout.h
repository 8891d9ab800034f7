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
#pragma once

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
namespace compressed_ply {

using geometry::kSH_C0;
using geometry::NumSHRestCoeffs;

inline constexpr int64_t kChunkSplats = 256;
inline constexpr int kChunkFloats = 18;
inline constexpr double kLogScaleClamp = 20.0;
inline constexpr double kOpacityAtAlpha0 = -40.0;  // the engine's values for alpha 0 and 255
inline constexpr double kOpacityAtAlpha255 = 40.0;
// sqrt(2) computed as the references write it, so that the rotation codes agree bit for bit.
inline const double kRotDecodeNorm = 1.0 / (std::sqrt(2.0) * 0.5);
inline const double kRotEncodeNorm = std::sqrt(2.0) * 0.5;
// Morton order is replaced by the input order when that is at most this much worse.
inline constexpr double kKeepInputOrderRatio = 1.25;

inline const char* const kChunkNames[kChunkFloats] = {
    "min_x",       "min_y",       "min_z",       "max_x",       "max_y",       "max_z",
    "min_scale_x", "min_scale_y", "min_scale_z", "max_scale_x", "max_scale_y", "max_scale_z",
    "min_r",       "min_g",       "min_b",       "max_r",       "max_g",       "max_b"};
inline const char* const kVertexNames[4] = {"packed_position", "packed_rotation", "packed_scale",
                                            "packed_color"};

// ---------------------------------------------------------------------------------------
// Decoding, shared by the reader and by the writer's exact-value check.

inline double Unorm(uint32_t value, int bits) {
    const uint32_t top = (1u << bits) - 1;
    return static_cast<double>(value & top) / top;
}

inline double Lerp(double a, double b, double t) { return a * (1.0 - t) + b * t; }

// Fields x, y, z of an 11/10/11 word: their shifts and widths.
inline constexpr int kShift111011[3] = {21, 11, 0};
inline constexpr int kBits111011[3] = {11, 10, 11};

inline float DecodeLinear(float lo, float hi, uint32_t code, int bits) {
    return static_cast<float>(Lerp(lo, hi, Unorm(code, bits)));
}

inline float DecodeScale(float lo, float hi, uint32_t code, int bits) {
    return DecodeLogScale(DecodeLinear(lo, hi, code, bits));
}

inline float ColourToFDc(double colour) { return static_cast<float>((colour - 0.5) / kSH_C0); }

inline float DecodeColour(bool bounds, float lo, float hi, uint32_t code) {
    const double t = Unorm(code, 8);
    return ColourToFDc(bounds ? Lerp(lo, hi, t) : t);
}

inline float DecodeOpacity(uint32_t code) {
    const double alpha = Unorm(code, 8);
    if (alpha <= 0.0) return static_cast<float>(kOpacityAtAlpha0);
    if (alpha >= 1.0) return static_cast<float>(kOpacityAtAlpha255);
    return static_cast<float>(-std::log(1.0 / alpha - 1.0));
}

// (w, x, y, z) as the reader hands it out, FinalizeColumns' normalisation included.
inline void DecodeRotation(uint32_t word, float out[4]) {
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

inline float DecodeSH(uint8_t byte) {
    const double unit = byte == 0 ? 0.0 : byte == 255 ? 1.0 : (byte + 0.5) / 256.0;
    return static_cast<float>((unit - 0.5) * 8.0);
}

}  // namespace compressed_ply
}  // namespace io
}  // namespace t
}  // namespace open3d
