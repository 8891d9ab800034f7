// Internal to t/io: one reader and writer per file format; PointCloudIO dispatches here.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {

geometry::PointCloud ReadPly(const std::string& filename, const ReadPointCloudOptions& options,
                             ReadPointCloudReport& report);
void WritePly(const std::string& filename, const geometry::PointCloud& cloud, PlyFormat format);

geometry::PointCloud ReadSplat(const std::string& filename, const ReadPointCloudOptions& options,
                               ReadPointCloudReport& report);
void WriteSplat(const std::string& filename, const geometry::PointCloud& cloud);

// Compressed and interchange formats (docs/formats.md). Each reader checks every size and
// offset against the file, names the file and the offending field in its errors, and hands
// its columns to FinalizeColumns.

/// SPZ (nianticlabs/spz): v1-3 (gzip) and v4 (zstd streams), SH degrees 0-3; stored RUB,
/// converted to and from the RDF axes of 3DGS. Written as v4. SpzReader.cpp, SpzWriter.cpp.
geometry::PointCloud ReadSpz(const std::string& filename, const ReadPointCloudOptions& options,
                             ReadPointCloudReport& report);
void WriteSpz(const std::string& filename, const geometry::PointCloud& cloud);

struct SplatColumns;
/// The axes DecodeSpz hands out: converted from the stored convention (RUB, or what
/// SPZ_ADOBE_coordinate_system names) to RDF, as a .spz file is read; or as stored, as
/// glTF's KHR_spz_gaussian_splats_compression takes them (GltfSpz.cpp says why).
enum class SpzAxes { kToRdf, kAsStored };
/// Decodes a whole SPZ held in memory (v1-3 gzip or v4, every check ReadSpz makes) into
/// `columns`, not yet finalised (FinalizeColumns). `label` opens every error and warning
/// (the quoted file name, or the file and the glTF object holding the SPZ); `filename`
/// names the file in the memory check.
void DecodeSpz(const uint8_t* data, size_t size, const std::string& filename,
               const std::string& label, SpzAxes axes, SplatColumns& columns,
               ReadPointCloudReport& report);

/// PlayCanvas compressed PLY (`element chunk` bounds + packed vertices, optional `sh`).
/// CompressedPlyReader.cpp, CompressedPlyWriter.cpp.
geometry::PointCloud ReadCompressedPly(const std::string& filename,
                                       const ReadPointCloudOptions& options,
                                       ReadPointCloudReport& report);
void WriteCompressedPly(const std::string& filename, const geometry::PointCloud& cloud);

/// PlayCanvas SOG v1, v2 and v3: a bundled .sog (zip) or a folder holding meta.json and its
/// WebP images (`filename` is the folder or its meta.json). Written as a bundled .sog of
/// version 2 (SogLayout.h says why). SogReader.cpp (v2, v3), SogV1Reader.cpp, SogWriter.cpp.
geometry::PointCloud ReadSog(const std::string& filename, const ReadPointCloudOptions& options,
                             ReadPointCloudReport& report);
void WriteSog(const std::string& filename, const geometry::PointCloud& cloud);

/// glTF 2.0 with KHR_gaussian_splatting: .gltf (external or data-URI buffers) and .glb.
/// Written as .glb, or as .gltf with one data-URI buffer. GltfFormat.cpp.
geometry::PointCloud ReadGltf(const std::string& filename, const ReadPointCloudOptions& options,
                              ReadPointCloudReport& report);
void WriteGltf(const std::string& filename, const geometry::PointCloud& cloud, bool binary);

/// mkkellogg's .ksplat, compression modes 0-2 (read only). KsplatFormat.cpp.
geometry::PointCloud ReadKsplat(const std::string& filename, const ReadPointCloudOptions& options,
                                ReadPointCloudReport& report);
/// Whether `bytes` start like a .ksplat: version 0.1+, mode 0-2, a splat count, and the
/// rest of the 4096-byte main header zero (GaussianSplats3D and splat-transform leave it so;
/// 128 records of a .splat are not all zero there). Names a .ksplat renamed to .splat.
bool LooksLikeKsplat(const uint8_t* bytes, uint64_t size);

/// The float32 log-scale whose exp (computed as the reader does, in double) gives back
/// `scale` exactly when such a value exists; otherwise the nearest one. Zero maps to a
/// finite log whose exp is zero.
float EncodeLogScale(float scale);
/// What the reader does: exp in double, rounded to float.
inline float DecodeLogScale(float log_scale) {
    return static_cast<float>(std::exp(static_cast<double>(log_scale)));
}

}  // namespace io
}  // namespace t
}  // namespace open3d
