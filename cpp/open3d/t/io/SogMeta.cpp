// What the SOG readers of every version share (SogMeta.h).
#include "open3d/t/io/SogMeta.h"

#include <cmath>
#include <fstream>

#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/io/InputPaths.h"
#include "open3d/t/io/SogLayout.h"

namespace open3d {
namespace t {
namespace io {
namespace sog {

namespace fs = std::filesystem;
using Json = nlohmann::json;

SogFiles::SogFiles(const std::string& filename) : filename_(filename) {
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

std::vector<uint8_t> SogFiles::Read(const std::string& name, size_t max_size) const {
    if (zip_) return zip_->Read(name, max_size);
    if (name == meta_name_ && file_) {
        if (file_->size() > max_size) {
            core::ThrowError("'{}': {} bytes, more than the {} allowed for meta.json", filename_,
                             file_->size(), max_size);
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

void Meta::Fail(const std::string& path, const std::string& what) const {
    core::ThrowError("'{}': {}: '{}' {}", filename, where, path, what);
}

const Json& Meta::Field(const Json& obj, const std::string& parent, const char* key) const {
    const std::string path = parent.empty() ? key : parent + "." + key;
    if (!obj.is_object()) Fail(parent, "is not an object");
    const auto it = obj.find(key);
    if (it == obj.end()) Fail(path, "is missing");
    return *it;
}

const Json* Meta::Optional(const Json& obj, const char* key) const {
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
}

int64_t Meta::Integer(const Json& v, const std::string& path, int64_t lo, int64_t hi) const {
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

double Meta::Number(const Json& v, const std::string& path) const {
    if (!v.is_number()) Fail(path, fmt::format("is {}, expected a number", v.dump()));
    const double d = v.get<double>();
    if (!std::isfinite(d)) Fail(path, "is not finite");
    return d;
}

std::vector<double> Meta::Numbers(const Json& parent, const std::string& parent_path,
                                  const char* key, size_t n) const {
    const std::string path = parent_path + "." + key;
    const Json& v = Field(parent, parent_path, key);
    if (!v.is_array() || v.size() != n) {
        Fail(path, fmt::format("must be an array of {} numbers", n));
    }
    std::vector<double> out(n);
    for (size_t i = 0; i < n; ++i) out[i] = Number(v[i], fmt::format("{}[{}]", path, i));
    return out;
}

std::vector<float> Meta::Codebook(const Json& parent, const std::string& parent_path) const {
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

std::vector<std::string> Meta::Files(const Json& parent, const std::string& parent_path,
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

Plane PlaneLoader::Load(const std::string& name, const std::string& field) {
    const std::vector<uint8_t> bytes = files_.Read(name, kMaxImageBytes);
    const std::string what = fmt::format("'{}': '{}' ({})", filename_, name, field);
    Plane plane{DecodeWebp(bytes.data(), bytes.size(), what, kMaxTexels)};
    const int w = plane.image.width, h = plane.image.height;
    if (width_ < 0) {
        width_ = w;
        height_ = h;
        first_name_ = name;
        first_field_ = field;
    } else if (w != width_ || h != height_) {
        core::ThrowError(
            "{} is {}x{}, but '{}' ({}) is {}x{}: per-Gaussian images must share one size", what, w,
            h, first_name_, first_field_, width_, height_);
    }
    if (int64_t(w) * h < count_) {
        core::ThrowError("{} is {}x{} = {} texels, fewer than count {}", what, w, h, int64_t(w) * h,
                         count_);
    }
    return plane;
}

Rgba8Image PlaneLoader::LoadOther(const std::string& name, const std::string& field) const {
    const std::vector<uint8_t> bytes = files_.Read(name, kMaxImageBytes);
    return DecodeWebp(bytes.data(), bytes.size(),
                      fmt::format("'{}': '{}' ({})", filename_, name, field), kMaxTexels);
}

void DecodePositions(const Plane& lo, const Plane& hi, const std::vector<double>& mins,
                     const std::vector<double>& maxs, int64_t count, float* positions) {
    core::ParallelFor(count, [&](int64_t i) {
        const uint8_t* l = lo.Texel(i);
        const uint8_t* u = hi.Texel(i);
        for (int a = 0; a < 3; ++a) {
            const double t = (l[a] | (u[a] << 8)) / 65535.0;
            positions[i * 3 + a] = static_cast<float>(UnLog(mins[a] * (1.0 - t) + maxs[a] * t));
        }
    });
}

void DecodeRotations(const Plane& quats, const std::string& filename, const std::string& name,
                     int64_t count, float* rot) {
    for (int64_t i = 0; i < count; ++i) {
        const uint8_t tag = quats.Texel(i)[3];
        if (tag < 252) {
            core::ThrowError(
                "'{}': '{}' (quats.files[0]): splat {} has alpha {}, expected 252..255 (the "
                "index of the omitted component)",
                filename, name, i, tag);
        }
    }
    core::ParallelFor(count, [&](int64_t i) {
        double q[4];
        DecodeQuat(quats.Texel(i), quats.Texel(i)[3] - 252, q);
        for (int c = 0; c < 4; ++c) rot[i * 4 + c] = static_cast<float>(q[c]);
    });
}

void DecodePositionsAndRotations(PlaneLoader& planes, const std::string& filename,
                                 const std::vector<std::string>& means_files,
                                 const std::vector<double>& mins, const std::vector<double>& maxs,
                                 const std::string& quats_file, int64_t count, int degree,
                                 SplatColumns& columns) {
    {
        const Plane lo = planes.Load(means_files[0], "means.files[0]");
        const Plane hi = planes.Load(means_files[1], "means.files[1]");
        columns.Allocate(filename, count, /*gaussian=*/true, degree);
        DecodePositions(lo, hi, mins, maxs, count, columns.positions.Data<float>());
    }
    const Plane quats = planes.Load(quats_file, "quats.files[0]");
    DecodeRotations(quats, filename, quats_file, count, columns.rot.Data<float>());
}

void DecodeShPalette(const Plane& labels, const Rgba8Image& centroids, int nc, int64_t palette,
                     const float value[256], const std::string& filename, const ShFiles& names,
                     int64_t count, float* rest) {
    for (int64_t i = 0; i < count; ++i) {
        const uint8_t* t = labels.Texel(i);
        const int64_t label = t[0] | (t[1] << 8);
        if ((palette > 0 && label >= palette) || label / 64 >= centroids.height) {
            const std::string count_text =
                palette > 0 ? fmt::format("shN.count is {} and ", palette) : "";
            core::ThrowError(
                "'{}': '{}' (shN.files[1]): splat {} has palette label {}, but {}'{}' holds {} "
                "rows of 64 entries",
                filename, names.labels, i, label, count_text, names.centroids, centroids.height);
        }
    }
    core::ParallelFor(count, [&](int64_t i) {
        const uint8_t* t = labels.Texel(i);
        const int64_t label = t[0] | (t[1] << 8);
        const uint8_t* row =
            centroids.rgba.data() + ((label / 64) * centroids.width + (label % 64) * nc) * 4;
        for (int j = 0; j < nc; ++j) {
            for (int c = 0; c < 3; ++c) rest[(i * nc + j) * 3 + c] = value[row[j * 4 + c]];
        }
    });
}

}  // namespace sog
}  // namespace io
}  // namespace t
}  // namespace open3d
