#include "open3d/t/io/PointCloudIO.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/RegularFile.h"
#include "open3d/t/io/FileFormats.h"

namespace open3d {
namespace t {
namespace io {
namespace {

namespace fs = std::filesystem;

std::string Lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

bool EndsWith(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() &&
           s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The format an extension names, for writing and for the warning when content disagrees.
bool FormatOfExtension(const std::string& filename, PointCloudFileFormat& format) {
    const std::string name = Lower(fs::path(filename).filename().string());
    const std::pair<const char*, PointCloudFileFormat> suffixes[] = {
        {".compressed.ply", PointCloudFileFormat::kCompressedPly},
        {".ply", PointCloudFileFormat::kPly},
        {".splat", PointCloudFileFormat::kSplat},
        {".spz", PointCloudFileFormat::kSpz},
        {".sog", PointCloudFileFormat::kSog},
        {"meta.json", PointCloudFileFormat::kSog},
        {".gltf", PointCloudFileFormat::kGltf},
        {".glb", PointCloudFileFormat::kGlb},
        {".ksplat", PointCloudFileFormat::kKsplat},
    };
    for (const auto& [suffix, f] : suffixes) {
        if (EndsWith(name, suffix)) {
            format = f;
            return true;
        }
    }
    return false;
}

constexpr const char* kSupported =
    ".ply, .compressed.ply, .splat, .spz, .sog (or a SOG folder), .gltf, .glb, .ksplat";

}  // namespace

const char* PointCloudFileFormatName(PointCloudFileFormat format) {
    switch (format) {
        case PointCloudFileFormat::kPly:
            return "3DGS PLY";
        case PointCloudFileFormat::kCompressedPly:
            return "compressed PLY";
        case PointCloudFileFormat::kSplat:
            return ".splat";
        case PointCloudFileFormat::kSpz:
            return "SPZ";
        case PointCloudFileFormat::kSog:
            return "SOG";
        case PointCloudFileFormat::kGltf:
            return "glTF";
        case PointCloudFileFormat::kGlb:
            return "glb";
        case PointCloudFileFormat::kKsplat:
            return ".ksplat";
    }
    return "unknown";
}

PointCloudFileFormat DetectPointCloudFileFormat(const std::string& filename) {
    std::error_code ec;
    if (fs::is_directory(filename, ec)) {
        if (fs::exists(fs::path(filename) / "meta.json", ec)) return PointCloudFileFormat::kSog;
        core::ThrowError("'{}' is a folder without a SOG meta.json", filename);
    }
    if (!fs::exists(filename, ec)) core::ThrowError("Cannot open '{}': no such file", filename);
    core::RequireRegularFile(filename);
    // The first bytes tell most formats apart; a PLY header is read until end_header to
    // tell the compressed layout (an `element chunk`) from the 3DGS one.
    std::ifstream in(filename, std::ios::binary);
    if (!in) core::ThrowError("'{}': cannot open: {}", filename, std::strerror(errno));
    std::string head(64 * 1024, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<size_t>(in.gcount()));
    if (head.empty()) core::ThrowError("'{}' is empty", filename);
    const auto starts = [&](const char* magic, size_t n) {
        return head.size() >= n && std::memcmp(head.data(), magic, n) == 0;
    };
    if (starts("ply\n", 4) || starts("ply\r\n", 5)) {
        const size_t end = head.find("end_header");
        const std::string header = head.substr(0, end);
        return header.find("\nelement chunk ") != std::string::npos
                   ? PointCloudFileFormat::kCompressedPly
                   : PointCloudFileFormat::kPly;
    }
    if (starts("NGSP", 4) || starts("\x1f\x8b", 2)) return PointCloudFileFormat::kSpz;
    if (starts("PK\x03\x04", 4)) return PointCloudFileFormat::kSog;
    if (starts("glTF", 4)) return PointCloudFileFormat::kGlb;
    PointCloudFileFormat by_extension;
    const bool known = FormatOfExtension(filename, by_extension);
    const size_t first = head.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
    if (first != std::string::npos && head[first] == '{') {
        // JSON: a SOG meta.json or a glTF; glTF requires an "asset" object.
        if (known && by_extension == PointCloudFileFormat::kSog) return by_extension;
        return PointCloudFileFormat::kGltf;
    }
    // No signature: .splat and .ksplat are known by their extension alone, and a file whose
    // extension names a format goes to that reader, which says what is wrong with it.
    if (known) return by_extension;
    core::ThrowError(
        "'{}': unknown extension '{}' and no known signature in its content (supported: {})",
        filename, Lower(fs::path(filename).extension().string()), kSupported);
}

ReadPointCloudReport ReadPointCloud(const std::string& filename, geometry::PointCloud& cloud,
                                    const ReadPointCloudOptions& options) {
    const PointCloudFileFormat format = DetectPointCloudFileFormat(filename);
    PointCloudFileFormat by_extension = format;
    const bool has_extension = FormatOfExtension(filename, by_extension);
    // .ply names both PLY layouts, and .gltf files are sometimes binary: no warning there.
    const bool compatible =
        (by_extension == PointCloudFileFormat::kPly &&
         format == PointCloudFileFormat::kCompressedPly) ||
        (by_extension == PointCloudFileFormat::kGltf && format == PointCloudFileFormat::kGlb);
    if (has_extension && by_extension != format && !compatible) {
        core::LogWarning("'{}': the content is {}, not {} as the extension says; reading it as {}",
                         filename, PointCloudFileFormatName(format),
                         PointCloudFileFormatName(by_extension), PointCloudFileFormatName(format));
    }
    ReadPointCloudReport report;
    // Read into a temporary so a failure leaves the caller's cloud untouched.
    geometry::PointCloud result;
    switch (format) {
        case PointCloudFileFormat::kPly:
            result = ReadPly(filename, options, report);
            break;
        case PointCloudFileFormat::kCompressedPly:
            result = ReadCompressedPly(filename, options, report);
            break;
        case PointCloudFileFormat::kSplat:
            result = ReadSplat(filename, options, report);
            break;
        case PointCloudFileFormat::kSpz:
            result = ReadSpz(filename, options, report);
            break;
        case PointCloudFileFormat::kSog:
            result = ReadSog(filename, options, report);
            break;
        case PointCloudFileFormat::kGltf:
        case PointCloudFileFormat::kGlb:
            result = ReadGltf(filename, options, report);
            break;
        case PointCloudFileFormat::kKsplat:
            result = ReadKsplat(filename, options, report);
            break;
    }
    cloud = std::move(result);
    return report;
}

void RequireGaussianSplat(const std::string& filename, const geometry::PointCloud& cloud) {
    std::string missing;
    for (const char* name : {geometry::gs_attr::kScale, geometry::gs_attr::kRot,
                             geometry::gs_attr::kOpacity, geometry::gs_attr::kFDc}) {
        if (!cloud.HasPointAttr(name)) missing += (missing.empty() ? "" : ", ") + std::string(name);
    }
    if (!missing.empty()) {
        core::ThrowError(
            "'{}' has no Gaussian splat attributes ({} {} missing{}): it is a plain point "
            "cloud, not a 3D Gaussian Splatting scene",
            filename, missing, missing.find(',') == std::string::npos ? "is" : "are",
            cloud.GetPointAttrNames().size() <= 1 ? "; the file has positions only" : "");
    }
    try {
        cloud.ValidateGaussianSplat();
    } catch (const core::Open3DError& e) {
        core::ThrowError("'{}': {}", filename, e.what());
    }
}

PointCloudFileFormat PointCloudFileFormatForWriting(const std::string& filename) {
    PointCloudFileFormat format;
    if (!FormatOfExtension(filename, format)) {
        core::ThrowError("'{}': unknown extension '{}' (supported: {})", filename,
                         Lower(fs::path(filename).extension().string()), kSupported);
    }
    if (format == PointCloudFileFormat::kSog && EndsWith(Lower(filename), "meta.json")) {
        core::ThrowError("'{}': SOG is written as a bundled .sog file", filename);
    }
    if (format == PointCloudFileFormat::kKsplat) {
        core::ThrowError(
            "'{}': .ksplat is read only; write .spz, .sog or .compressed.ply "
            "for a compressed file",
            filename);
    }
    return format;
}

void WritePointCloud(const std::string& filename, const geometry::PointCloud& cloud,
                     const WritePointCloudOptions& options) {
    switch (PointCloudFileFormatForWriting(filename)) {
        case PointCloudFileFormat::kPly:
            WritePly(filename, cloud, options.ply_format);
            break;
        case PointCloudFileFormat::kCompressedPly:
            WriteCompressedPly(filename, cloud);
            break;
        case PointCloudFileFormat::kSplat:
            WriteSplat(filename, cloud);
            break;
        case PointCloudFileFormat::kSpz:
            WriteSpz(filename, cloud);
            break;
        case PointCloudFileFormat::kSog:
            WriteSog(filename, cloud);
            break;
        case PointCloudFileFormat::kGltf:
            WriteGltf(filename, cloud, /*binary=*/false);
            break;
        case PointCloudFileFormat::kGlb:
            WriteGltf(filename, cloud, /*binary=*/true);
            break;
        case PointCloudFileFormat::kKsplat:
            break;  // refused by PointCloudFileFormatForWriting
    }
}

}  // namespace io
}  // namespace t
}  // namespace open3d
