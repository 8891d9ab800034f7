// Reading and writing Gaussian splat clouds: 3DGS PLY (binary LE/BE, ASCII), antimatter15
// .splat, SPZ, PlayCanvas compressed PLY, SOG, glTF KHR_gaussian_splatting and .ksplat
// (docs/formats.md). Failures throw core::Open3DError naming the file and the problem.
#pragma once

#include <cstdint>
#include <string>

#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace t {
namespace io {

struct ReadPointCloudOptions {
    /// Splats with NaN/Inf values are refused by default; true drops them instead
    /// (the count is reported in ReadPointCloudReport and logged).
    bool drop_non_finite = false;
};

struct ReadPointCloudReport {
    int64_t num_points = 0;
    int64_t dropped_non_finite = 0;
    int64_t trailing_bytes = 0;  // bytes after the declared vertices (warned, ignored)
};

/// The file formats ReadPointCloud knows.
enum class PointCloudFileFormat {
    kPly,            ///< 3DGS PLY (binary or ASCII)
    kCompressedPly,  ///< PlayCanvas compressed PLY (`element chunk`)
    kSplat,          ///< antimatter15 .splat
    kSpz,            ///< Niantic SPZ, v1-3 (gzip) or v4
    kSog,            ///< PlayCanvas SOG: bundled .sog (zip) or a folder / its meta.json
    kGltf,           ///< glTF 2.0 JSON (.gltf) with KHR_gaussian_splatting
    kGlb,            ///< binary glTF (.glb)
    kKsplat,         ///< GaussianSplats3D .ksplat
};
/// Its name as docs/formats.md spells it (e.g. "SPZ").
const char* PointCloudFileFormatName(PointCloudFileFormat format);

/// The format of a file from its content: magic bytes and headers (PLY, compressed PLY,
/// SPZ, zip/SOG, glb, glTF JSON); the formats without a signature (.splat, .ksplat) and a
/// SOG folder by their extension or layout. Throws naming the file when neither tells.
PointCloudFileFormat DetectPointCloudFileFormat(const std::string& filename);

/// Reads a splat file of any format above, detected by content (DetectPointCloudFileFormat;
/// a warning is logged when the extension says otherwise). On failure throws and leaves
/// `cloud` unchanged.
ReadPointCloudReport ReadPointCloud(const std::string& filename, geometry::PointCloud& cloud,
                                    const ReadPointCloudOptions& options = {});

/// Throws naming the file and the missing attributes unless `cloud`, read from `filename`,
/// is a Gaussian splat cloud (renderers need scale, rot, opacity and f_dc; a plain xyz PLY
/// has positions only).
void RequireGaussianSplat(const std::string& filename, const geometry::PointCloud& cloud);

enum class PlyFormat { BinaryLittleEndian, BinaryBigEndian, Ascii };

struct WritePointCloudOptions {
    PlyFormat ply_format = PlyFormat::BinaryLittleEndian;
};

/// Writes the format the extension names (case-insensitive): .ply (3DGS layout,
/// log-scales), .compressed.ply, .splat, .spz (v4), .sog (bundled, version 2), .glb, .gltf (one
/// data-URI buffer). Writing SH a format cannot hold (.splat: degree 0) drops it with a warning.
/// The format WritePointCloud writes to `filename`, from its extension; throws naming the
/// file for an unknown extension or a read-only format (.ksplat, a SOG meta.json), so a
/// caller can refuse a bad output before reading anything.
PointCloudFileFormat PointCloudFileFormatForWriting(const std::string& filename);

void WritePointCloud(const std::string& filename, const geometry::PointCloud& cloud,
                     const WritePointCloudOptions& options = {});

}  // namespace io
}  // namespace t
}  // namespace open3d
