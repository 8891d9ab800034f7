// The SOG reader: versions 2 and 3 here, version 1 in SogV1Reader.cpp (layouts and choices:
// SogLayout.h).
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/SogLayout.h"
#include "open3d/t/io/SogMeta.h"
#include "open3d/t/io/SplatColumns.h"
#include "open3d/t/io/WebpImage.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using Json = nlohmann::json;
using namespace sog;

// meta.json's "model" (splat-transform 3.2 and later: absent or "default" for ordinary 3D
// Gaussians, "antialiased", "2dgs") and "antialias" (a boolean; this library's writer writes
// false). They say how the scene was trained and so how it must be rendered; the cloud has no
// place for either, so the reader says it here (SogLayout.h, docs/formats.md).
void CheckModel(const Meta& meta) {
    bool antialiased = false;
    if (const Json* model = meta.Optional(meta.root, "model"); model != nullptr) {
        if (!model->is_string()) {
            meta.Fail("model", fmt::format("is {}, expected a string", model->dump()));
        }
        const std::string value = model->get<std::string>();
        if (value == "2dgs") {
            // Surfels with no third axis, evaluated by ray-surfel intersection: drawn as 3D
            // Gaussians they are flat ellipsoids seen through the wrong footprint.
            meta.Fail("model",
                      "is '2dgs' (2D Gaussian splats, surfels): this renderer draws 3D Gaussians "
                      "and cannot draw them faithfully, so the file is not read");
        }
        if (value == "antialiased") {
            antialiased = true;
            core::LogWarning(
                "'{}': SOG model 'antialiased' (meta.json 'model'; trained with mip-splatting "
                "antialiasing): render it with antialiasing on",
                meta.filename);
        } else if (value != "default") {
            core::LogWarning(
                "'{}': SOG model '{}' (meta.json 'model') is not one this reader knows "
                "('default', 'antialiased', '2dgs'); read as ordinary 3D Gaussians",
                meta.filename, value);
        }
    }
    if (const Json* aa = meta.Optional(meta.root, "antialias"); aa != nullptr) {
        if (!aa->is_boolean()) {
            meta.Fail("antialias", fmt::format("is {}, expected true or false", aa->dump()));
        }
        if (aa->get<bool>() && !antialiased) {
            core::LogWarning(
                "'{}': SOG meta.json 'antialias' is true (trained with antialiasing): render "
                "it with antialiasing on",
                meta.filename);
        }
    }
}

// Versions 2 and 3 (the layout of SogLayout.h).
geometry::PointCloud ReadSogV2(const SogFiles& files, const Meta& meta,
                               const ReadPointCloudOptions& options, ReadPointCloudReport& report) {
    const std::string& filename = meta.filename;
    const Json& root = meta.root;
    const int64_t count = meta.Integer(meta.Field(root, "", "count"), "count", 0, kMaxTexels);

    const Json& means = meta.Field(root, "", "means");
    const std::vector<double> mins = meta.Numbers(means, "means", "mins", 3);
    const std::vector<double> maxs = meta.Numbers(means, "means", "maxs", 3);
    const std::vector<std::string> means_files = meta.Files(means, "means", 2);
    const Json& scales = meta.Field(root, "", "scales");
    const std::vector<float> scale_codebook = meta.Codebook(scales, "scales");
    const std::string scales_file = meta.Files(scales, "scales", 1)[0];
    const std::string quats_file = meta.Files(meta.Field(root, "", "quats"), "quats", 1)[0];
    const Json& sh0 = meta.Field(root, "", "sh0");
    const std::vector<float> sh0_codebook = meta.Codebook(sh0, "sh0");
    const std::string sh0_file = meta.Files(sh0, "sh0", 1)[0];

    int degree = 0;
    int64_t palette = 0;
    std::vector<float> shn_codebook;
    std::vector<std::string> shn_files;
    if (const Json* shn = meta.Optional(root, "shN"); shn != nullptr && !shn->is_null()) {
        degree =
            static_cast<int>(meta.Integer(meta.Field(*shn, "shN", "bands"), "shN.bands", 1, 3));
        palette = meta.Integer(meta.Field(*shn, "shN", "count"), "shN.count", 1, kMaxPalette);
        shn_codebook = meta.Codebook(*shn, "shN");
        shn_files = meta.Files(*shn, "shN", 2);
    }
    PlaneLoader planes(files, filename, count);

    SplatColumns columns;
    DecodePositionsAndRotations(planes, filename, means_files, mins, maxs, quats_file, count,
                                degree, columns);
    {
        const Plane plane = planes.Load(scales_file, "scales.files[0]");
        std::array<float, kCodebookSize> linear;
        for (int k = 0; k < kCodebookSize; ++k) linear[k] = DecodeLogScale(scale_codebook[k]);
        float* scale = columns.scale.Data<float>();
        core::ParallelFor(count, [&](int64_t i) {
            for (int a = 0; a < 3; ++a) scale[i * 3 + a] = linear[plane.Texel(i)[a]];
        });
    }
    {
        const Plane plane = planes.Load(sh0_file, "sh0.files[0]");
        float* f_dc = columns.f_dc.Data<float>();
        float* opacity = columns.opacity.Data<float>();
        core::ParallelFor(count, [&](int64_t i) {
            const uint8_t* t = plane.Texel(i);
            for (int c = 0; c < 3; ++c) f_dc[i * 3 + c] = sh0_codebook[t[c]];
            opacity[i] = Logit(t[3]);
        });
    }
    if (degree > 0) {
        const int nc = geometry::NumSHRestCoeffs(degree);
        const Plane labels = planes.Load(shn_files[1], "shN.files[1]");
        const Rgba8Image centroids = planes.LoadOther(shn_files[0], "shN.files[0]");
        if (centroids.width != 64 * nc) {
            core::ThrowError(
                "'{}': '{}' (shN.files[0]) is {} texels wide; {} band(s) need 64 * {} = {}",
                filename, shn_files[0], centroids.width, degree, nc, 64 * nc);
        }
        DecodeShPalette(labels, centroids, nc, palette, shn_codebook.data(), filename,
                        {shn_files[0], shn_files[1]}, count, columns.f_rest.Data<float>());
    }
    return FinalizeColumns(filename, columns, options, report);
}

}  // namespace

geometry::PointCloud ReadSog(const std::string& filename, const ReadPointCloudOptions& options,
                             ReadPointCloudReport& report) {
    const SogFiles files(filename);
    const std::vector<uint8_t> meta_bytes = files.Read(files.MetaName(), kMaxMetaBytes);
    const Json root = Json::parse(meta_bytes.begin(), meta_bytes.end(), nullptr, false);
    if (root.is_discarded()) core::ThrowError("'{}': meta.json is not valid JSON", filename);
    if (!root.is_object()) core::ThrowError("'{}': meta.json is not a JSON object", filename);
    Meta meta{filename, root};
    CheckModel(meta);

    // No "version" is the version-1 ("SOGS") layout, as PlayCanvas's engine and
    // splat-transform read it; its errors say so, for a newer file that lost its version.
    const Json* version_field = meta.Optional(root, "version");
    const int64_t version =
        version_field == nullptr ? 1 : meta.Integer(*version_field, "version", 0, 1 << 30);
    if (version == 1) {
        meta.where = version_field == nullptr ? "meta.json (no 'version': SOG version 1)"
                                              : "meta.json (SOG version 1)";
        return ReadSogV1(files, meta, options, report);
    }
    if (version != 2 && version != 3) {
        meta.Fail("version", fmt::format("is {}; versions 1, 2 and 3 are supported", version));
    }
    return ReadSogV2(files, meta, options, report);
}

}  // namespace io
}  // namespace t
}  // namespace open3d
