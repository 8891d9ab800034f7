// PlayCanvas SOG ("Spatially Ordered Gaussians"): meta.json plus lossless WebP images, either
// as files in a folder or bundled in a zip (.sog) with the same names at the archive root.
//
// Specification read: the PlayCanvas developer manual, "The SOG Format" (version 2, the text of
// docs/user-manual/gaussian-splatting/formats/sog.md in playcanvas/developer-site) and the
// first part of the current page, which names version 3 as current with the same file set
// and channels as version 2 (the rest of the version-3 page could not be consulted). Layout,
// per Gaussian i at texel i (row-major, x = i % W, y = i / W, every per-Gaussian image W x H
// with count <= W * H; trailing texels are ignored):
//   means_l / means_u (RGB): low / high byte of a 16-bit code q per axis; the position is
//     n = lerp(means.mins[a], means.maxs[a], q / 65535), x = sign(n) * (exp(|n|) - 1)
//     (the inverse of the writer's sign(x) * log(|x| + 1)).
//   quats (RGBA): smallest three. A = 252 + m, m = index of the omitted (largest) component in
//     (w, x, y, z) = PLY rot_0..rot_3; R, G, B = the other three in that order, each
//     (byte / 255 * 2 - 1) / sqrt(2); the omitted one is sqrt(max(0, 1 - a^2 - b^2 - c^2)).
//   scales (RGB): indices into scales.codebook (256 floats, natural-log scales, as the PLY).
//   sh0 (RGBA): RGB index sh0.codebook (256 floats: f_dc), A = sigmoid(opacity) * 255.
//   shN (optional; bands 1..3, Nc = (bands + 1)^2 - 1): shN_labels RG = a 16-bit palette
//     index (R + 256 G) below shN.count; shN_centroids is 64 * Nc texels wide, palette entry
//     n's coefficient j at texel ((n % 64) * Nc + j, n / 64), its RGB indexing shN.codebook
//     (256 floats) for the R, G, B channel of that coefficient.
// Coordinates: SOG stores the axes of 3DGS PLY files (the version-2 page says so and that
// version 3 is the same; splat-transform reads and writes SOG in its PLY frame), i.e. the
// RDF axes of this library: no conversion either way.
//
// Behaviour of the reference implementations relied on beyond the text: scales.codebook
// holds natural-log scales (every splat-transform file, monkey_0001.sog included); the
// centroid texture is 64 * Nc texels wide (the page's table says 96 for one band, the
// engine and splat-transform use 192); a codebook whose first entry is null (older writers
// serialised a NaN) gets codebook[1] + (codebook[1] - codebook[255]) / 255 there, as the
// PlayCanvas engine does. Alpha 0 and 255 map to logits of +-13.8 (1e-6 margin), like .splat.
//
// Version 1 ("SOGS": meta.json without "version", or version 1), as PlayCanvas's engine
// (gsplat-sog-data.js and its shaders) and splat-transform (read-sog-v1.ts; the writers
// write-sogs.ts of mid-2025 and playcanvas/sogs) read and wrote it. The same images, texel
// addressing, positions (means.mins / maxs, log transform) and quats as above; instead of
// codebooks every 8-bit value is lerp(lo, hi, byte / 255):
//   count = means.shape[0] (no "count"); scales RGB with scales.mins / maxs[0..2] (natural-log
//   scales); sh0 RGB f_dc with sh0.mins / maxs[0..2] and A the opacity logit (not a sigmoid)
//   with sh0.mins / maxs[3]; shN.mins / shN.maxs are single numbers for every palette
//   coefficient; there is no shN.count or shN.bands: the bands follow the centroid image's
//   width (192, 512, 960 = 64 * Nc for 1, 2, 3 bands) and the palette is its rows * 64.
// The other shape entries, dtype and shN.shape (the two writers disagree on it) are not used.
//
// Choices of this reader: versions 2 and 3 are decoded with the layout above and version 1 as
// just said; a quats alpha outside 252..255 or a palette label at or above shN.count (version
// 1: outside the centroid image) is an error naming the splat; files named in meta.json must
// be plain relative names (no "..", no absolute paths); all per-Gaussian images must have the
// same size; at most 2^24 texels per image. Version 1 refuses quats.encoding other than
// "quaternion_packed", shN.quantization other than 8, and the first SOGS layout of spring
// 2025 (an "opacities" image; no PlayCanvas tool reads it now).
// meta.json "model" (splat-transform 3.2) and "antialias": "antialiased" or antialias true
// are read with a warning to render with antialiasing on; "2dgs" (2D Gaussian surfels) is
// refused, as this library draws 3D Gaussians only; an unknown model is read with a warning.
//
// The writer writes a bundled .sog of version 2 (kWriteVersion; the version-3 changes could
// not be consulted, and version 2 is the one every PlayCanvas tool reads): texture sides
// multiples of 4 as PlayCanvas writes them; the cloud's own order (no Morton sort, so written
// and read splats match by index); positions rounded to the nearest 16-bit code; quaternions
// in the unit-decoding mode that reproduces them best; scale (log) and f_dc codebooks by 1D
// k-means over the three columns together (exact when there are <= 256 distinct values);
// opacity rounded to 8 bits; the shN palette exact up to 65536 distinct coefficient vectors,
// else k-means trained on a sample with a palette size set by a compute budget (1024 at
// 150k splats of SH 3). Deterministic; a written file read back and written again gives the
// same values.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace open3d {
namespace t {
namespace io {
namespace sog {

inline constexpr int kWriteVersion = 2;
// At most 16.7M splats (4096 x 4096 texels): lossless WebP compresses a constant image to a
// few bytes, so the image sizes, not the file size, bound what a reader allocates.
inline constexpr int64_t kMaxTexels = int64_t(1) << 24;
inline constexpr size_t kMaxMetaBytes = size_t(64) << 20;
inline constexpr size_t kMaxImageBytes = size_t(1) << 30;
inline constexpr int kCodebookSize = 256;
inline constexpr int kMaxPalette = 65536;
inline constexpr double kAlphaMargin = 1e-6;
inline constexpr double kSqrt2 = 1.4142135623730951;

inline float Logit(uint8_t alpha) {
    const double a = std::clamp(alpha / 255.0, kAlphaMargin, 1.0 - kAlphaMargin);
    return static_cast<float>(std::log(a / (1.0 - a)));
}

inline double UnLog(double n) { return n < 0 ? -(std::exp(-n) - 1.0) : std::exp(n) - 1.0; }

inline double LogTransform(double x) { return x < 0 ? -std::log(-x + 1.0) : std::log(x + 1.0); }

// Decodes a smallest-three quaternion to (w, x, y, z); mode = alpha - 252 in 0..3.
inline void DecodeQuat(const uint8_t* t, int mode, double q[4]) {
    double v[3];
    for (int k = 0; k < 3; ++k) v[k] = (t[k] / 255.0 * 2.0 - 1.0) / kSqrt2;
    const double d = std::sqrt(std::max(0.0, 1.0 - (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])));
    for (int c = 0, k = 0; c < 4; ++c) q[c] = c == mode ? d : v[k++];
}

}  // namespace sog
}  // namespace io
}  // namespace t
}  // namespace open3d
