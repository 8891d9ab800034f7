// Internal to t/io: what the SOG readers of every version share (SogReader.cpp for versions 2
// and 3, SogV1Reader.cpp for version 1): the files of one SOG, meta.json's validating
// accessors and the per-Gaussian images. Every error names the file and the field.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/t/io/SplatColumns.h"
#include "open3d/t/io/WebpImage.h"
#include "open3d/t/io/ZipArchive.h"

namespace open3d {
namespace t {
namespace io {
namespace sog {

// The files of one SOG: zip entries or files in a folder, by the names meta.json gives.
class SogFiles {
public:
    explicit SogFiles(const std::string& filename);

    const std::string& MetaName() const { return meta_name_; }
    /// The bytes of `name`; throws naming the SOG and `name` when it is missing, not a
    /// regular file or larger than max_size.
    std::vector<uint8_t> Read(const std::string& name, size_t max_size) const;

private:
    std::string filename_;
    std::unique_ptr<MappedFile> file_;
    std::unique_ptr<ZipReader> zip_;
    std::filesystem::path folder_;
    std::string meta_name_;
};

// Validating accessors for meta.json; every error names the file, `where` (what the reader
// took the meta.json for, e.g. "meta.json (SOG version 1)") and the field path.
struct Meta {
    const std::string& filename;
    const nlohmann::json& root;
    std::string where = "meta.json";

    [[noreturn]] void Fail(const std::string& path, const std::string& what) const;
    const nlohmann::json& Field(const nlohmann::json& obj, const std::string& parent,
                                const char* key) const;
    const nlohmann::json* Optional(const nlohmann::json& obj, const char* key) const;
    int64_t Integer(const nlohmann::json& v, const std::string& path, int64_t lo, int64_t hi) const;
    double Number(const nlohmann::json& v, const std::string& path) const;
    /// parent[key]: an array of exactly n finite numbers.
    std::vector<double> Numbers(const nlohmann::json& parent, const std::string& parent_path,
                                const char* key, size_t n) const;
    /// parent.codebook: 256 numbers (a null first entry is rebuilt as PlayCanvas does).
    std::vector<float> Codebook(const nlohmann::json& parent, const std::string& parent_path) const;
    /// parent.files: exactly n plain relative file names.
    std::vector<std::string> Files(const nlohmann::json& parent, const std::string& parent_path,
                                   size_t n) const;
};

// One decoded per-Gaussian image.
struct Plane {
    Rgba8Image image;
    const uint8_t* Texel(int64_t i) const { return image.rgba.data() + i * 4; }
};

// Loads the per-Gaussian images of one SOG: each must have the first one's size and at
// least `count` texels (texel i belongs to splat i in every one of them).
class PlaneLoader {
public:
    PlaneLoader(const SogFiles& files, const std::string& filename, int64_t count)
        : files_(files), filename_(filename), count_(count) {}
    /// `field` is where meta.json names the image (e.g. "means.files[0]").
    Plane Load(const std::string& name, const std::string& field);
    /// An image that is not per-Gaussian (the SH palette): only bounded in size.
    Rgba8Image LoadOther(const std::string& name, const std::string& field) const;

private:
    const SogFiles& files_;
    const std::string& filename_;
    int64_t count_;
    int width_ = -1, height_ = -1;
    std::string first_name_, first_field_;
};

/// Positions from means_l / means_u (the same in every version): per axis the 16-bit code
/// (low byte in `lo`, high in `hi`) lerped between mins and maxs, then un-log-transformed.
void DecodePositions(const Plane& lo, const Plane& hi, const std::vector<double>& mins,
                     const std::vector<double>& maxs, int64_t count, float* positions);

/// Rotations (w, x, y, z) from quats (the same in every version); throws naming the file,
/// `name` and the splat whose alpha is not 252..255.
void DecodeRotations(const Plane& quats, const std::string& filename, const std::string& name,
                     int64_t count, float* rot);

/// Allocates `columns` for `count` splats of SH degree `degree` (the memory check) and fills
/// their positions (means_files: means_l, means_u) and rotations (quats_file): what every
/// version stores the same way.
void DecodePositionsAndRotations(PlaneLoader& planes, const std::string& filename,
                                 const std::vector<std::string>& means_files,
                                 const std::vector<double>& mins, const std::vector<double>& maxs,
                                 const std::string& quats_file, int64_t count, int degree,
                                 SplatColumns& columns);

/// The names of the SH images, for errors: shN.files[0] (centroids), shN.files[1] (labels).
struct ShFiles {
    std::string centroids, labels;
};

/// f_rest [count, nc, 3] from the SH palette (the same layout in every version): splat i's
/// entry n = R + 256 G of its labels texel; coefficient j of entry n is centroids texel
/// ((n % 64) * nc + j, n / 64), whose R, G, B bytes `value` maps to the R, G, B coefficient.
/// Throws naming the splat when n is outside the image or at or above `palette` (> 0 where
/// meta.json gives a palette size).
void DecodeShPalette(const Plane& labels, const Rgba8Image& centroids, int nc, int64_t palette,
                     const float value[256], const std::string& filename, const ShFiles& names,
                     int64_t count, float* rest);

/// Reads a SOG version 1 (no "version" in meta.json, or 1): SogV1Reader.cpp.
geometry::PointCloud ReadSogV1(const SogFiles& files, const Meta& meta,
                               const ReadPointCloudOptions& options, ReadPointCloudReport& report);

}  // namespace sog
}  // namespace io
}  // namespace t
}  // namespace open3d
