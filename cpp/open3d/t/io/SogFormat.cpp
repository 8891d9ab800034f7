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
// Choices of this reader: versions 2 and 3 are decoded with the layout above (version 1,
// without a "version" field, is refused); a quats alpha outside 252..255 or a palette label
// at or above shN.count is an error naming the splat; files named in meta.json must be plain
// relative names (no "..", no absolute paths); all per-Gaussian images must have the same
// size; at most 2^24 texels per image.
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

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/SplatColumns.h"
#include "open3d/t/io/WebpImage.h"
#include "open3d/t/io/ZipArchive.h"

namespace open3d {
namespace t {
namespace io {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr int kWriteVersion = 2;
// At most 16.7M splats (4096 x 4096 texels): lossless WebP compresses a constant image to a
// few bytes, so the image sizes, not the file size, bound what a reader allocates.
constexpr int64_t kMaxTexels = int64_t(1) << 24;
constexpr size_t kMaxMetaBytes = size_t(64) << 20;
constexpr size_t kMaxImageBytes = size_t(1) << 30;
constexpr int kCodebookSize = 256;
constexpr int kMaxPalette = 65536;
constexpr double kAlphaMargin = 1e-6;
constexpr double kSqrt2 = 1.4142135623730951;

// ---------------------------------------------------------------------------------------
// Reading

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
        if (!fs::is_regular_file(path, ec)) {
            core::ThrowError("'{}': '{}' is missing (looked for '{}')", filename_, name,
                             path.string());
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

float Logit(uint8_t alpha) {
    const double a = std::clamp(alpha / 255.0, kAlphaMargin, 1.0 - kAlphaMargin);
    return static_cast<float>(std::log(a / (1.0 - a)));
}

double UnLog(double n) { return n < 0 ? -(std::exp(-n) - 1.0) : std::exp(n) - 1.0; }

double LogTransform(double x) { return x < 0 ? -std::log(-x + 1.0) : std::log(x + 1.0); }

// Decodes a smallest-three quaternion to (w, x, y, z); mode = alpha - 252 in 0..3.
void DecodeQuat(const uint8_t* t, int mode, double q[4]) {
    double v[3];
    for (int k = 0; k < 3; ++k) v[k] = (t[k] / 255.0 * 2.0 - 1.0) / kSqrt2;
    const double d = std::sqrt(std::max(0.0, 1.0 - (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])));
    for (int c = 0, k = 0; c < 4; ++c) q[c] = c == mode ? d : v[k++];
}

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
        columns.Allocate(count, /*gaussian=*/true, degree);
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

// ---------------------------------------------------------------------------------------
// Writing

namespace {

// 1D k-means with 256 entries: exact (the sorted distinct values) when there are at most
// 256 of them; otherwise Lloyd iterations over the sorted values from quantile seeds.
// Returns the codebook (ascending) and one label per value.
std::vector<float> Quantise1D(const std::vector<float>& values, std::vector<uint8_t>& labels,
                              int iterations = 32) {
    std::vector<float> sorted = values;
    std::sort(sorted.begin(), sorted.end());
    std::vector<float> distinct = sorted;
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    std::vector<float> codebook;
    if (distinct.size() <= size_t(kCodebookSize)) {
        codebook = distinct;
    } else {
        const size_t n = sorted.size();
        std::vector<double> prefix(n + 1, 0.0);
        for (size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + sorted[i];
        std::vector<double> c(kCodebookSize);
        for (int k = 0; k < kCodebookSize; ++k)
            c[k] = sorted[((2 * k + 1) * n) / (2 * kCodebookSize)];
        std::vector<size_t> bounds(kCodebookSize + 1);
        for (int it = 0; it < iterations; ++it) {
            bounds[0] = 0;
            bounds[kCodebookSize] = n;
            for (int k = 1; k < kCodebookSize; ++k) {
                const double mid = 0.5 * (c[k - 1] + c[k]);
                bounds[k] = std::lower_bound(sorted.begin(), sorted.end(), mid) - sorted.begin();
                bounds[k] = std::max(bounds[k], bounds[k - 1]);
            }
            bool changed = false;
            for (int k = 0; k < kCodebookSize; ++k) {
                if (bounds[k + 1] == bounds[k]) continue;  // empty: keep the centroid
                const double mean =
                    (prefix[bounds[k + 1]] - prefix[bounds[k]]) / double(bounds[k + 1] - bounds[k]);
                changed = changed || mean != c[k];
                c[k] = mean;
            }
            std::sort(c.begin(), c.end());
            if (!changed) break;
        }
        for (double v : c) codebook.push_back(static_cast<float>(v));
        std::sort(codebook.begin(), codebook.end());
    }
    codebook.resize(kCodebookSize, codebook.empty() ? 0.0f : codebook.back());
    labels.resize(values.size());
    core::ParallelFor(int64_t(values.size()), [&](int64_t i) {
        const float v = values[i];
        // First entry not below v, then the nearer of it and its predecessor.
        int k = int(std::lower_bound(codebook.begin(), codebook.end(), v) - codebook.begin());
        if (k == kCodebookSize) k = kCodebookSize - 1;
        if (k > 0 && double(v) - codebook[k - 1] <= double(codebook[k]) - v) --k;
        labels[i] = static_cast<uint8_t>(k);
    });
    return codebook;
}

struct RowHash {
    const float* data;
    int dims;
    size_t operator()(int64_t row) const {
        uint64_t h = 1469598103934665603ull;
        const auto* bytes = reinterpret_cast<const uint8_t*>(data + row * dims);
        for (int b = 0; b < dims * 4; ++b) h = (h ^ bytes[b]) * 1099511628211ull;
        return static_cast<size_t>(h);
    }
};
struct RowEqual {
    const float* data;
    int dims;
    bool operator()(int64_t a, int64_t b) const {
        return std::memcmp(data + a * dims, data + b * dims, size_t(dims) * 4) == 0;
    }
};

// Palette of SH coefficient vectors (n rows of dims floats). With at most 65536 distinct rows
// the palette is those rows, exactly. Otherwise k-means: seeds are K distinct rows and the
// Lloyd rounds run on a sample of at most kSample rows (both drawn with a fixed seed), then
// every row takes its nearest centroid; K is the largest power of two, 256..65536, that keeps
// the multiply-adds K * dims * (kSample * kIterations + n) within kBudget.
std::vector<float> Palette(const float* rows, int64_t n, int dims, std::vector<int32_t>& labels) {
    constexpr int kIterations = 4;
    constexpr int64_t kSample = 32768;
    constexpr double kBudget = 1.5e10;  // about 6-8 s on two cores with the kernel below
    labels.assign(n, 0);
    std::unordered_map<int64_t, int32_t, RowHash, RowEqual> index(16, RowHash{rows, dims},
                                                                  RowEqual{rows, dims});
    std::vector<int64_t> distinct;
    for (int64_t i = 0; i < n; ++i) {
        const auto [it, inserted] = index.emplace(i, int32_t(distinct.size()));
        if (inserted) distinct.push_back(i);
        labels[i] = it->second;
    }
    if (distinct.size() <= size_t(kMaxPalette)) {
        std::vector<float> palette(distinct.size() * dims);
        for (size_t p = 0; p < distinct.size(); ++p) {
            std::copy_n(rows + distinct[p] * dims, dims, palette.begin() + p * dims);
        }
        return palette;
    }
    const int64_t sample_size = std::min(n, kSample);
    const int64_t k_budget =
        int64_t(kBudget / (double(dims) * (double(sample_size) * kIterations + double(n))));
    int64_t k = 256;
    while (k * 2 <= std::min<int64_t>(k_budget, kMaxPalette)) k *= 2;
    std::mt19937_64 rng(0x5065C0DEull);
    const auto shuffle_front = [&rng](std::vector<int64_t>& v, int64_t m) {
        for (int64_t p = 0; p < m; ++p) {
            std::uniform_int_distribution<int64_t> pick(p, int64_t(v.size()) - 1);
            std::swap(v[p], v[pick(rng)]);
        }
    };
    shuffle_front(distinct, k);
    std::vector<int64_t> sample(n);
    for (int64_t i = 0; i < n; ++i) sample[i] = i;
    shuffle_front(sample, sample_size);
    sample.resize(sample_size);
    std::sort(sample.begin(), sample.end());
    // Transposed palette [dims][k]: the distance loop then runs over centroids, which the
    // compiler vectorises (a float sum over dims would not be, without reassociation).
    std::vector<float> columns(k * dims);
    for (int64_t p = 0; p < k; ++p) {
        for (int j = 0; j < dims; ++j) columns[j * k + p] = rows[distinct[p] * dims + j];
    }
    // Nearest centroid of rows[which(i)] into label(i), for i in [0, m).
    const auto assign = [&](int64_t m, const auto& which, int32_t* out) {
        core::ParallelForRange(
            m,
            [&](int64_t begin, int64_t end) {
                std::vector<float> distance(k);
                for (int64_t i = begin; i < end; ++i) {
                    const float* x = rows + which(i) * dims;
                    std::fill(distance.begin(), distance.end(), 0.0f);
                    for (int j = 0; j < dims; ++j) {
                        const float xj = x[j];
                        const float* c = columns.data() + j * k;
                        float* d = distance.data();
                        for (int64_t p = 0; p < k; ++p) {
                            const float e = xj - c[p];
                            d[p] += e * e;
                        }
                    }
                    out[i] = int32_t(std::min_element(distance.begin(), distance.end()) -
                                     distance.begin());
                }
            },
            64);
    };
    std::vector<int32_t> sample_labels(sample_size);
    std::vector<double> sums(k * dims);
    std::vector<int64_t> counts(k);
    for (int it = 0; it < kIterations; ++it) {
        assign(
            sample_size, [&](int64_t i) { return sample[i]; }, sample_labels.data());
        std::fill(sums.begin(), sums.end(), 0.0);
        std::fill(counts.begin(), counts.end(), 0);
        for (int64_t i = 0; i < sample_size; ++i) {
            const int32_t p = sample_labels[i];
            ++counts[p];
            for (int j = 0; j < dims; ++j) sums[p * dims + j] += rows[sample[i] * dims + j];
        }
        for (int64_t p = 0; p < k; ++p) {
            if (counts[p] == 0) continue;  // empty: keep the centroid
            for (int j = 0; j < dims; ++j) {
                columns[j * k + p] = static_cast<float>(sums[p * dims + j] / counts[p]);
            }
        }
    }
    assign(
        n, [](int64_t i) { return i; }, labels.data());
    std::vector<float> palette(k * dims);
    for (int64_t p = 0; p < k; ++p) {
        for (int j = 0; j < dims; ++j) palette[p * dims + j] = columns[j * k + p];
    }
    return palette;
}

// Smallest-three bytes of a unit quaternion (w, x, y, z) in the mode that decodes closest
// to it (the largest component, or a near tie that reproduces it better) among the modes that
// decode to a unit quaternion.
void EncodeQuat(const double q[4], uint8_t out[4]) {
    int largest = 0;
    for (int c = 1; c < 4; ++c) {
        if (std::abs(q[c]) > std::abs(q[largest])) largest = c;
    }
    double best = std::numeric_limits<double>::max();
    for (int mode = 0; mode < 4; ++mode) {
        const double sign = q[mode] < 0 ? -1.0 : 1.0;
        uint8_t t[4];
        for (int c = 0, k = 0; c < 4; ++c) {
            if (c == mode) continue;
            const double v = sign * q[c] * kSqrt2 * 0.5 + 0.5;
            t[k++] = static_cast<uint8_t>(std::clamp(std::lround(v * 255.0), 0L, 255L));
        }
        t[3] = static_cast<uint8_t>(252 + mode);
        // Only modes whose three stored components leave room for the fourth (a^2 + b^2 + c^2
        // <= 1) decode to a unit quaternion, which reads back and re-encodes to these bytes.
        double stored = 0;
        for (int k = 0; k < 3; ++k) {
            const double v = (t[k] / 255.0 * 2.0 - 1.0) / kSqrt2;
            stored += v * v;
        }
        if (stored > 1.0 && mode != largest) continue;
        double d[4];
        DecodeQuat(t, mode, d);
        const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + d[3] * d[3]);
        const double dot = std::abs(d[0] * q[0] + d[1] * q[1] + d[2] * q[2] + d[3] * q[3]) / norm;
        const double error = 1.0 - dot;
        if (error < best) {
            best = error;
            std::copy_n(t, 4, out);
        }
    }
}

Json FloatArray(const std::vector<float>& v) {
    Json a = Json::array();
    for (float f : v) a.push_back(double(f));
    return a;
}

}  // namespace

void WriteSog(const std::string& filename, const geometry::PointCloud& cloud) {
    if (!cloud.IsGaussianSplat()) {
        core::ThrowError(
            "Cannot write '{}': SOG needs a Gaussian splat cloud (scale, rot, opacity, f_dc)",
            filename);
    }
    const geometry::GaussianSplatArrays a = cloud.GetGaussianSplatArrays();
    const int64_t n = a.num_points;
    if (n > kMaxTexels) {
        core::ThrowError("Cannot write '{}': {} splats, more than the {} a SOG written here holds",
                         filename, n, kMaxTexels);
    }
    for (int64_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            if (!std::isfinite(a.positions[i * 3 + c])) {
                core::ThrowError("Cannot write '{}': splat {} has a non-finite position", filename,
                                 i);
            }
        }
    }
    // Texture size as PlayCanvas writes it: a near-square, both sides multiples of 4.
    const int width = std::max(4, int(std::ceil(std::sqrt(double(n)) / 4.0)) * 4);
    const int height = std::max(4, int(std::ceil(double(n) / width / 4.0)) * 4);
    const size_t texels = size_t(width) * height;
    auto plane = [&] {
        Rgba8Image image;
        image.width = width;
        image.height = height;
        image.rgba.insert(image.rgba.end(), texels * 4, uint8_t(0));
        return image;
    };

    // Positions: 16-bit codes of the log transform between its per-axis min and max.
    double mins[3], maxs[3];
    for (int c = 0; c < 3; ++c) {
        mins[c] = n > 0 ? std::numeric_limits<double>::max() : 0.0;
        maxs[c] = n > 0 ? std::numeric_limits<double>::lowest() : 0.0;
    }
    for (int64_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            const double l = LogTransform(a.positions[i * 3 + c]);
            mins[c] = std::min(mins[c], l);
            maxs[c] = std::max(maxs[c], l);
        }
    }
    Rgba8Image means_l = plane(), means_u = plane(), quats = plane(), scales = plane(),
               sh0 = plane();
    core::ParallelFor(n, [&](int64_t i) {
        for (int c = 0; c < 3; ++c) {
            const double range = maxs[c] - mins[c];
            const double t =
                range > 0 ? (LogTransform(a.positions[i * 3 + c]) - mins[c]) / range : 0.0;
            const long q = std::clamp(std::lround(t * 65535.0), 0L, 65535L);
            means_l.rgba[i * 4 + c] = uint8_t(q & 0xff);
            means_u.rgba[i * 4 + c] = uint8_t(q >> 8);
        }
        means_l.rgba[i * 4 + 3] = 255;
        means_u.rgba[i * 4 + 3] = 255;
    });

    std::vector<uint8_t> zero_quat(n, 0);
    core::ParallelFor(n, [&](int64_t i) {
        const float* r = a.rot + i * 4;
        double q[4];
        double norm = 0;
        for (int c = 0; c < 4; ++c) norm += double(r[c]) * r[c];
        norm = std::sqrt(norm);
        if (!(norm > 0) || !std::isfinite(norm)) {
            zero_quat[i] = 1;
            return;
        }
        for (int c = 0; c < 4; ++c) q[c] = r[c] / norm;
        EncodeQuat(q, &quats.rgba[i * 4]);
    });
    if (const auto it = std::find(zero_quat.begin(), zero_quat.end(), 1); it != zero_quat.end()) {
        core::ThrowError("Cannot write '{}': splat {} has a zero or non-finite rotation quaternion",
                         filename, it - zero_quat.begin());
    }

    // Scales (as natural logs, like the PLY) and DC colours: one 256-entry codebook each.
    std::vector<float> log_scales(n * 3), dc(n * 3);
    core::ParallelFor(n * 3, [&](int64_t k) {
        log_scales[k] = EncodeLogScale(a.scale[k]);
        dc[k] = a.f_dc[k];
    });
    for (const auto* column : {&log_scales, &dc}) {
        for (int64_t k = 0; k < n * 3; ++k) {
            if (!std::isfinite((*column)[k])) {
                core::ThrowError("Cannot write '{}': splat {} has a non-finite {}", filename, k / 3,
                                 column == &dc ? "f_dc" : "scale");
            }
        }
    }
    std::vector<uint8_t> scale_labels, dc_labels;
    const std::vector<float> scale_codebook = Quantise1D(log_scales, scale_labels);
    const std::vector<float> dc_codebook = Quantise1D(dc, dc_labels);
    core::ParallelFor(n, [&](int64_t i) {
        for (int c = 0; c < 3; ++c) {
            scales.rgba[i * 4 + c] = scale_labels[i * 3 + c];
            sh0.rgba[i * 4 + c] = dc_labels[i * 3 + c];
        }
        scales.rgba[i * 4 + 3] = 255;
        const double alpha = 1.0 / (1.0 + std::exp(-double(a.opacity[i])));
        sh0.rgba[i * 4 + 3] =
            static_cast<uint8_t>(std::clamp(std::lround(alpha * 255.0), 0L, 255L));
    });

    std::vector<std::pair<std::string, Rgba8Image>> images;
    images.emplace_back("means_l.webp", std::move(means_l));
    images.emplace_back("means_u.webp", std::move(means_u));
    images.emplace_back("scales.webp", std::move(scales));
    images.emplace_back("quats.webp", std::move(quats));
    images.emplace_back("sh0.webp", std::move(sh0));

    Json meta = Json::object();
    meta["version"] = kWriteVersion;
    meta["asset"] = {{"generator", "open3d t/io SogFormat"}};
    meta["count"] = n;
    meta["antialias"] = false;
    meta["means"] = {{"mins", Json::array({mins[0], mins[1], mins[2]})},
                     {"maxs", Json::array({maxs[0], maxs[1], maxs[2]})},
                     {"files", Json::array({"means_l.webp", "means_u.webp"})}};
    meta["scales"] = {{"codebook", FloatArray(scale_codebook)},
                      {"files", Json::array({"scales.webp"})}};
    meta["quats"] = {{"files", Json::array({"quats.webp"})}};
    meta["sh0"] = {{"codebook", FloatArray(dc_codebook)}, {"files", Json::array({"sh0.webp"})}};

    if (a.sh_degree > 0 && n > 0) {
        const int nc = a.num_rest;
        const int dims = nc * 3;
        for (int64_t k = 0; k < n * dims; ++k) {
            if (!std::isfinite(a.f_rest[k])) {
                core::ThrowError("Cannot write '{}': splat {} has a non-finite f_rest", filename,
                                 k / dims);
            }
        }
        std::vector<int32_t> labels;
        const std::vector<float> palette = Palette(a.f_rest, n, dims, labels);
        const int64_t entries = int64_t(palette.size()) / dims;
        std::vector<uint8_t> coefficient_labels;
        const std::vector<float> codebook = Quantise1D(palette, coefficient_labels);
        Rgba8Image centroids;
        centroids.width = 64 * nc;
        centroids.height = int((entries + 63) / 64);
        centroids.rgba.insert(centroids.rgba.end(), size_t(centroids.width) * centroids.height * 4,
                              uint8_t(0));
        for (int64_t p = 0; p < entries; ++p) {
            uint8_t* row = centroids.rgba.data() + ((p / 64) * centroids.width + (p % 64) * nc) * 4;
            for (int j = 0; j < nc; ++j) {
                for (int c = 0; c < 3; ++c)
                    row[j * 4 + c] = coefficient_labels[p * dims + j * 3 + c];
                row[j * 4 + 3] = 255;
            }
        }
        Rgba8Image label_image = plane();
        for (int64_t i = 0; i < n; ++i) {
            label_image.rgba[i * 4 + 0] = uint8_t(labels[i] & 0xff);
            label_image.rgba[i * 4 + 1] = uint8_t(labels[i] >> 8);
            label_image.rgba[i * 4 + 3] = 255;
        }
        images.emplace_back("shN_centroids.webp", std::move(centroids));
        images.emplace_back("shN_labels.webp", std::move(label_image));
        meta["shN"] = {{"count", entries},
                       {"bands", a.sh_degree},
                       {"codebook", FloatArray(codebook)},
                       {"files", Json::array({"shN_centroids.webp", "shN_labels.webp"})}};
    }

    std::vector<std::vector<uint8_t>> encoded(images.size());
    core::ParallelFor(
        int64_t(images.size()),
        [&](int64_t k) { encoded[k] = EncodeWebpLossless(images[k].second); }, 1);
    ZipWriter zip;
    for (size_t k = 0; k < images.size(); ++k) zip.Add(images[k].first, encoded[k]);
    const std::string text = meta.dump();
    zip.Add("meta.json", std::vector<uint8_t>(text.begin(), text.end()));
    WriteFileBytes(filename, zip.Finish());
}

}  // namespace io
}  // namespace t
}  // namespace open3d
