// The SOG version-1 reader (layout and choices: SogLayout.h, "Version 1").
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/SogLayout.h"
#include "open3d/t/io/SogMeta.h"
#include "open3d/t/io/SplatColumns.h"

namespace open3d {
namespace t {
namespace io {
namespace sog {
namespace {

using Json = nlohmann::json;
using Table = std::array<float, 256>;

// What byte b decodes to: lo + (hi - lo) * b / 255, as a float. Version 1 stores every 8-bit
// attribute so, with lo / hi from meta.json; lo_path / hi_path name them in errors.
Table LerpTable(const Meta& meta, double lo, double hi, const std::string& lo_path,
                const std::string& hi_path) {
    Table table;
    for (int b = 0; b < 256; ++b) {
        const double t = b / 255.0;
        table[b] = static_cast<float>(lo * (1.0 - t) + hi * t);
    }
    // The ends are lo and hi exactly, and the table is monotonic between them.
    if (!std::isfinite(table[0])) meta.Fail(lo_path, fmt::format("({}) overflows float", lo));
    if (!std::isfinite(table[255])) meta.Fail(hi_path, fmt::format("({}) overflows float", hi));
    return table;
}

// One table per channel of an attribute with per-channel mins / maxs.
std::vector<Table> ChannelTables(const Meta& meta, const Json& parent, const std::string& path,
                                 size_t channels) {
    const std::vector<double> mins = meta.Numbers(parent, path, "mins", channels);
    const std::vector<double> maxs = meta.Numbers(parent, path, "maxs", channels);
    std::vector<Table> tables;
    for (size_t c = 0; c < channels; ++c) {
        tables.push_back(LerpTable(meta, mins[c], maxs[c], fmt::format("{}.mins[{}]", path, c),
                                   fmt::format("{}.maxs[{}]", path, c)));
    }
    return tables;
}

// Version 1 has no band count: the palette image is 64 entries of Nc texels wide.
int BandsOfCentroidWidth(int width) {
    for (int degree = 1; degree <= 3; ++degree) {
        if (width == 64 * geometry::NumSHRestCoeffs(degree)) return degree;
    }
    return 0;
}

}  // namespace

geometry::PointCloud ReadSogV1(const SogFiles& files, const Meta& meta,
                               const ReadPointCloudOptions& options, ReadPointCloudReport& report) {
    const std::string& filename = meta.filename;
    const Json& root = meta.root;
    // The first SOGS layout (spring 2025: an 'opacities' image, quaternions with mins and
    // maxs, labels in two images) is read by no PlayCanvas tool today.
    if (meta.Optional(root, "opacities") != nullptr) {
        meta.Fail("opacities",
                  "is present: the first SOGS layout (opacity in an image of its own), which "
                  "PlayCanvas's tools no longer read and this reader does not either");
    }

    const Json& means = meta.Field(root, "", "means");
    const Json& shape = meta.Field(means, "means", "shape");
    if (!shape.is_array() || shape.empty()) {
        meta.Fail("means.shape", "must be an array [count, 3]");
    }
    const int64_t count = meta.Integer(shape[0], "means.shape[0]", 0, kMaxTexels);
    const std::vector<double> mins = meta.Numbers(means, "means", "mins", 3);
    const std::vector<double> maxs = meta.Numbers(means, "means", "maxs", 3);
    const std::vector<std::string> means_files = meta.Files(means, "means", 2);

    const Json& scales = meta.Field(root, "", "scales");
    const std::vector<Table> log_scale = ChannelTables(meta, scales, "scales", 3);
    const std::string scales_file = meta.Files(scales, "scales", 1)[0];

    const Json& quats = meta.Field(root, "", "quats");
    if (const Json* encoding = meta.Optional(quats, "encoding");
        encoding != nullptr && *encoding != "quaternion_packed") {
        meta.Fail("quats.encoding",
                  fmt::format("is {}; version 1 packs quaternions as 'quaternion_packed'",
                              encoding->dump()));
    }
    const std::string quats_file = meta.Files(quats, "quats", 1)[0];

    // f_dc in R, G, B; the opacity logit in A.
    const Json& sh0 = meta.Field(root, "", "sh0");
    const std::vector<Table> sh0_tables = ChannelTables(meta, sh0, "sh0", 4);
    const std::string sh0_file = meta.Files(sh0, "sh0", 1)[0];

    const Json* shn = meta.Optional(root, "shN");
    if (shn != nullptr && shn->is_null()) shn = nullptr;
    Table shn_table{};
    std::vector<std::string> shn_files;
    if (shn != nullptr) {
        // One range for every coefficient of every palette entry.
        const double lo = meta.Number(meta.Field(*shn, "shN", "mins"), "shN.mins");
        const double hi = meta.Number(meta.Field(*shn, "shN", "maxs"), "shN.maxs");
        shn_table = LerpTable(meta, lo, hi, "shN.mins", "shN.maxs");
        if (const Json* bits = meta.Optional(*shn, "quantization");
            bits != nullptr && meta.Integer(*bits, "shN.quantization", 0, 64) != 8) {
            meta.Fail(
                "shN.quantization",
                fmt::format("is {}; the palette is read as 8-bit (every writer's)", bits->dump()));
        }
        shn_files = meta.Files(*shn, "shN", 2);
    }

    PlaneLoader planes(files, filename, count);
    Rgba8Image centroids;
    int degree = 0;
    if (shn != nullptr) {
        centroids = planes.LoadOther(shn_files[0], "shN.files[0]");
        degree = BandsOfCentroidWidth(centroids.width);
        if (degree == 0) {
            core::ThrowError(
                "'{}': '{}' (shN.files[0]) is {} texels wide; version 1 tells the SH bands by "
                "that width: 192 (1 band), 512 (2) or 960 (3)",
                filename, shn_files[0], centroids.width);
        }
    }

    SplatColumns columns;
    DecodePositionsAndRotations(planes, filename, means_files, mins, maxs, quats_file, count,
                                degree, columns);
    {
        const Plane plane = planes.Load(scales_file, "scales.files[0]");
        std::array<Table, 3> linear;
        for (int a = 0; a < 3; ++a) {
            for (int b = 0; b < 256; ++b) linear[a][b] = DecodeLogScale(log_scale[a][b]);
        }
        float* scale = columns.scale.Data<float>();
        core::ParallelFor(count, [&](int64_t i) {
            for (int a = 0; a < 3; ++a) scale[i * 3 + a] = linear[a][plane.Texel(i)[a]];
        });
    }
    {
        const Plane plane = planes.Load(sh0_file, "sh0.files[0]");
        float* f_dc = columns.f_dc.Data<float>();
        float* opacity = columns.opacity.Data<float>();
        core::ParallelFor(count, [&](int64_t i) {
            const uint8_t* t = plane.Texel(i);
            for (int c = 0; c < 3; ++c) f_dc[i * 3 + c] = sh0_tables[c][t[c]];
            opacity[i] = sh0_tables[3][t[3]];
        });
    }
    if (degree > 0) {
        const Plane labels = planes.Load(shn_files[1], "shN.files[1]");
        DecodeShPalette(labels, centroids, geometry::NumSHRestCoeffs(degree), /*palette=*/0,
                        shn_table.data(), filename, {shn_files[0], shn_files[1]}, count,
                        columns.f_rest.Data<float>());
    }
    return FinalizeColumns(filename, columns, options, report);
}

}  // namespace sog
}  // namespace io
}  // namespace t
}  // namespace open3d
