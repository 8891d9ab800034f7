// The SOG reader (layout and choices: SogLayout.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/InputPaths.h"
#include "open3d/t/io/SogLayout.h"
#include "open3d/t/io/SplatColumns.h"
#include "open3d/t/io/WebpImage.h"
#include "open3d/t/io/ZipArchive.h"

namespace open3d {
namespace t {
namespace io {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace sog;

// The files of one SOG: zip entries or files in a folder, by the names meta.json gives.
class SogFiles {
public:
    explicit SogFiles(const std::string& filename) : filename_(filename) {
        std::error_code ec;
        if (fs::is_directory(filename, ec)) {
            folder_ = fs::path(filename);
            meta_name_ = "meta.json";
            return;
        }
        file_ = std::make_unique<MappedFile>(filename);
        if (LooksLikeZip(file_->data(), file_->size())) {
            zip_ = std::make_unique<ZipReader>(file_->data(), file_->size(), "'" + filename + "'");
            meta_name_ = "meta.json";
            if (!zip_->Has(meta_name_)) {
                std::string names;
                for (const std::string& name : zip_->Names())
                    names += (names.empty() ? "" : ", ") + name;
                core::ThrowError("'{}': the archive has no meta.json at its root (entries: {})",
                                 filename, names);
            }
        } else {
            // A meta.json (any name): the images are beside it.
            folder_ = fs::path(filename).parent_path();
            meta_name_ = fs::path(filename).filename().string();
        }
    }

    const std::string& MetaName() const { return meta_name_; }

    std::vector<uint8_t> Read(const std::string& name, size_t max_size) const {
        if (zip_) return zip_->Read(name, max_size);
        if (name == meta_name_ && file_) {
            if (file_->size() > max_size) {
                core::ThrowError("'{}': {} bytes, more than the {} allowed for meta.json",
                                 filename_, file_->size(), max_size);
            }
            return std::vector<uint8_t>(file_->data(), file_->data() + file_->size());
        }
        const fs::path path = folder_ / name;
        std::error_code ec;
        if (const std::string problem = InputPathProblem(path.string(), false); !problem.empty()) {
            core::ThrowError("'{}': its '{}' cannot be read: {}", filename_, name, problem);
        }
        const uintmax_t size = fs::file_size(path, ec);
        if (ec || size > max_size) {
            core::ThrowError("'{}': '{}' is larger than the {} bytes allowed", filename_, name,
                             max_size);
        }
        std::ifstream in(path, std::ios::binary);
        std::vector<uint8_t> bytes(static_cast<size_t>(size));
        if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size))) {
            core::ThrowError("'{}': cannot read '{}'", filename_, path.string());
        }
        return bytes;
    }

private:
    std::string filename_;
    std::unique_ptr<MappedFile> file_;
    std::unique_ptr<ZipReader> zip_;
    fs::path folder_;
    std::string meta_name_;
};

// Validating accessors for meta.json; every error names the file and the field path.
struct Meta {
    const std::string& filename;
    const Json& root;

    [[noreturn]] void Fail(const std::string& path, const std::string& what) const {
        core::ThrowError("'{}': meta.json: '{}' {}", filename, path, what);
    }
    const Json& Field(const Json& obj, const std::string& parent, const char* key) const {
        const std::string path = parent.empty() ? key : parent + "." + key;
        if (!obj.is_object()) Fail(parent, "is not an object");
        const auto it = obj.find(key);
        if (it == obj.end()) Fail(path, "is missing");
        return *it;
    }
    const Json* Optional(const Json& obj, const char* key) const {
        const auto it = obj.find(key);
        return it == obj.end() ? nullptr : &*it;
    }
    int64_t Integer(const Json& v, const std::string& path, int64_t lo, int64_t hi) const {
        if (v.is_number_unsigned()) {
            const uint64_t u = v.get<uint64_t>();
            if (u <= uint64_t(hi) && int64_t(u) >= lo) return int64_t(u);
        } else if (v.is_number_integer()) {
            const int64_t i = v.get<int64_t>();
            if (i >= lo && i <= hi) return i;
        } else {
            Fail(path, fmt::format("is {}, expected an integer", v.dump()));
        }
        Fail(path, fmt::format("is {}, outside {}..{}", v.dump(), lo, hi));
    }
    double Number(const Json& v, const std::string& path) const {
        if (!v.is_number()) Fail(path, fmt::format("is {}, expected a number", v.dump()));
        const double d = v.get<double>();
        if (!std::isfinite(d)) Fail(path, "is not finite");
        return d;
    }
    std::vector<double> Numbers(const Json& parent, const std::string& parent_path, const char* key,
                                size_t n) const {
        const std::string path = parent_path + "." + key;
        const Json& v = Field(parent, parent_path, key);
        if (!v.is_array() || v.size() != n) {
            Fail(path, fmt::format("must be an array of {} numbers", n));
        }
        std::vector<double> out(n);
        for (size_t i = 0; i < n; ++i) out[i] = Number(v[i], fmt::format("{}[{}]", path, i));
        return out;
    }
    std::vector<float> Codebook(const Json& parent, const std::string& parent_path) const {
        const std::string path = parent_path + ".codebook";
        const Json& v = Field(parent, parent_path, "codebook");
        if (!v.is_array() || v.size() != size_t(kCodebookSize)) {
            Fail(path, fmt::format("must be an array of {} numbers (has {})", kCodebookSize,
                                   v.is_array() ? v.size() : 0));
        }
        std::vector<double> d(kCodebookSize);
        for (int i = (v[0].is_null() ? 1 : 0); i < kCodebookSize; ++i) {
            d[i] = Number(v[i], fmt::format("{}[{}]", path, i));
        }
        // As the PlayCanvas engine does for writers that serialised a NaN as null.
        if (v[0].is_null()) d[0] = d[1] + (d[1] - d[255]) / 255.0;
        std::vector<float> out(kCodebookSize);
        for (int i = 0; i < kCodebookSize; ++i) {
            out[i] = static_cast<float>(d[i]);
            if (!std::isfinite(out[i])) Fail(fmt::format("{}[{}]", path, i), "overflows float");
        }
        return out;
    }
    std::vector<std::string> Files(const Json& parent, const std::string& parent_path,
                                   size_t n) const {
        const std::string path = parent_path + ".files";
        const Json& v = Field(parent, parent_path, "files");
        if (!v.is_array() || v.size() != n) Fail(path, fmt::format("must list {} file name(s)", n));
        std::vector<std::string> out;
        for (size_t i = 0; i < n; ++i) {
            const std::string item = fmt::format("{}[{}]", path, i);
            if (!v[i].is_string()) Fail(item, "is not a string");
            const std::string name = v[i].get<std::string>();
            const fs::path p(name);
            bool bad = name.empty() || p.is_absolute() || p.has_root_path();
            for (const auto& part : p) bad = bad || part == "..";
            if (bad) Fail(item, fmt::format("'{}' is not a relative file name", name));
            out.push_back(name);
        }
        return out;
    }
};

// One decoded per-Gaussian image, checked against the others' size and the count.
struct Plane {
    Rgba8Image image;
    const uint8_t* Texel(int64_t i) const { return image.rgba.data() + i * 4; }
};

}  // namespace

geometry::PointCloud ReadSog(const std::string& filename, const ReadPointCloudOptions& options,
                             ReadPointCloudReport& report) {
    const SogFiles files(filename);
    const std::vector<uint8_t> meta_bytes = files.Read(files.MetaName(), kMaxMetaBytes);
    const Json root = Json::parse(meta_bytes.begin(), meta_bytes.end(), nullptr, false);
    if (root.is_discarded()) core::ThrowError("'{}': meta.json is not valid JSON", filename);
    if (!root.is_object()) core::ThrowError("'{}': meta.json is not a JSON object", filename);
    const Meta meta{filename, root};

    if (meta.Optional(root, "version") == nullptr) {
        meta.Fail("version",
                  "is missing (a SOG version 1 / SOGS meta.json, which this reader does not "
                  "read; versions 2 and 3 are supported)");
    }
    const int64_t version = meta.Integer(root["version"], "version", 0, 1 << 30);
    if (version != 2 && version != 3) {
        meta.Fail("version", fmt::format("is {}; versions 2 and 3 are supported", version));
    }
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
    if (const Json* aa = meta.Optional(root, "antialias");
        aa != nullptr && aa->is_boolean() && aa->get<bool>()) {
        core::LogWarning(
            "'{}': the scene was trained with anti-aliasing (meta.json 'antialias'); the cloud "
            "does not carry that flag",
            filename);
    }

    // Every per-Gaussian image: same size, at least count texels.
    int width = -1, height = -1;
    auto load = [&](const std::string& name, const std::string& field) {
        const std::vector<uint8_t> bytes = files.Read(name, kMaxImageBytes);
        const std::string what = fmt::format("'{}': '{}' ({})", filename, name, field);
        Plane plane{DecodeWebp(bytes.data(), bytes.size(), what, kMaxTexels)};
        const int w = plane.image.width, h = plane.image.height;
        if (width < 0) {
            width = w;
            height = h;
        } else if (w != width || h != height) {
            core::ThrowError(
                "{} is {}x{}, but '{}' ({}) is {}x{}: per-Gaussian images must share one size",
                what, w, h, means_files[0], "means.files[0]", width, height);
        }
        if (int64_t(w) * h < count) {
            core::ThrowError("{} is {}x{} = {} texels, fewer than count {}", what, w, h,
                             int64_t(w) * h, count);
        }
        return plane;
    };

    SplatColumns columns;
    {
        const Plane lo = load(means_files[0], "means.files[0]");
        const Plane hi = load(means_files[1], "means.files[1]");
        columns.Allocate(filename, count, /*gaussian=*/true, degree);
        float* positions = columns.positions.Data<float>();
        core::ParallelFor(count, [&](int64_t i) {
            const uint8_t* l = lo.Texel(i);
            const uint8_t* u = hi.Texel(i);
            for (int a = 0; a < 3; ++a) {
                const double t = (l[a] | (u[a] << 8)) / 65535.0;
                positions[i * 3 + a] = static_cast<float>(UnLog(mins[a] * (1.0 - t) + maxs[a] * t));
            }
        });
    }
    {
        const Plane quats = load(quats_file, "quats.files[0]");
        for (int64_t i = 0; i < count; ++i) {
            const uint8_t tag = quats.Texel(i)[3];
            if (tag < 252) {
                core::ThrowError(
                    "'{}': '{}' (quats.files[0]): splat {} has alpha {}, expected 252..255 (the "
                    "index of the omitted component)",
                    filename, quats_file, i, tag);
            }
        }
        float* rot = columns.rot.Data<float>();
        core::ParallelFor(count, [&](int64_t i) {
            double q[4];
            DecodeQuat(quats.Texel(i), quats.Texel(i)[3] - 252, q);
            for (int c = 0; c < 4; ++c) rot[i * 4 + c] = static_cast<float>(q[c]);
        });
    }
    {
        const Plane plane = load(scales_file, "scales.files[0]");
        std::array<float, kCodebookSize> linear;
        for (int k = 0; k < kCodebookSize; ++k) linear[k] = DecodeLogScale(scale_codebook[k]);
        float* scale = columns.scale.Data<float>();
        core::ParallelFor(count, [&](int64_t i) {
            for (int a = 0; a < 3; ++a) scale[i * 3 + a] = linear[plane.Texel(i)[a]];
        });
    }
    {
        const Plane plane = load(sh0_file, "sh0.files[0]");
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
        const Plane labels = load(shn_files[1], "shN.files[1]");
        const std::vector<uint8_t> bytes = files.Read(shn_files[0], kMaxImageBytes);
        const Rgba8Image centroids = DecodeWebp(
            bytes.data(), bytes.size(),
            fmt::format("'{}': '{}' (shN.files[0])", filename, shn_files[0]), kMaxTexels);
        if (centroids.width != 64 * nc) {
            core::ThrowError(
                "'{}': '{}' (shN.files[0]) is {} texels wide; {} band(s) need 64 * {} = {}",
                filename, shn_files[0], centroids.width, degree, nc, 64 * nc);
        }
        for (int64_t i = 0; i < count; ++i) {
            const uint8_t* t = labels.Texel(i);
            const int64_t label = t[0] | (t[1] << 8);
            if (label >= palette || label / 64 >= centroids.height) {
                core::ThrowError(
                    "'{}': '{}' (shN.files[1]): splat {} has palette label {}, but shN.count is "
                    "{} and '{}' holds {} rows of 64 entries",
                    filename, shn_files[1], i, label, palette, shn_files[0], centroids.height);
            }
        }
        float* rest = columns.f_rest.Data<float>();
        core::ParallelFor(count, [&](int64_t i) {
            const uint8_t* t = labels.Texel(i);
            const int64_t label = t[0] | (t[1] << 8);
            const uint8_t* row =
                centroids.rgba.data() + ((label / 64) * centroids.width + (label % 64) * nc) * 4;
            for (int j = 0; j < nc; ++j) {
                for (int c = 0; c < 3; ++c) {
                    rest[(i * nc + j) * 3 + c] = shn_codebook[row[j * 4 + c]];
                }
            }
        });
    }
    return FinalizeColumns(filename, columns, options, report);
}

}  // namespace io
}  // namespace t
}  // namespace open3d
