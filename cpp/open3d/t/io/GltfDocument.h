// Internal to t/io: a glTF 2.0 asset as the splat reader sees it: the .gltf JSON or the .glb
// container, its buffers (GLB BIN chunk, base64 data URIs, external files beside the
// .gltf), bufferViews and accessors decoded to float. Every error names the file and the
// glTF object (accessor, bufferView, buffer, GLB chunk). GltfDocument.cpp.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/t/io/SplatColumns.h"

namespace open3d {
namespace t {
namespace io {
namespace gltf {

using Json = nlohmann::json;

struct Span {
    const uint8_t* data = nullptr;
    uint64_t size = 0;
};

/// One component type an attribute accepts (glTF componentType code, normalized flag).
struct Allowed {
    int component_type;
    bool normalized;
};

/// A JSON value for an error message: scalars as JSON text (cut at 40 characters), arrays
/// and objects by their kind only.
std::string BriefJson(const Json& value);

class GltfDocument {
public:
    /// Maps the file, splits a .glb into its chunks, parses the JSON, checks asset.version
    /// and extensionsRequired. GLB bytes past the declared length go to report.trailing_bytes.
    GltfDocument(const std::string& filename, ReadPointCloudReport& report);

    const Json& Root() const { return root_; }
    const std::string& Filename() const { return filename_; }
    /// Bytes of the file and of the external buffers loaded so far (bounds instancing).
    uint64_t InputBytes() const { return input_bytes_; }

    template <typename... Args>
    [[noreturn]] void Fail(fmt::format_string<Args...> format, Args&&... args) const {
        core::ThrowError("'{}': {}", filename_, fmt::format(format, std::forward<Args>(args)...));
    }

    // JSON access; `where` names the object in errors (e.g. "mesh 0 primitive 1").
    const Json* Find(const Json& object, const char* key) const;
    /// A non-negative integer below 2^53; `fallback` when absent (required when none).
    uint64_t Uint(const Json& object, const char* key, const std::string& where,
                  std::optional<uint64_t> fallback = std::nullopt) const;
    double Number(const Json& value, const std::string& where) const;
    std::string String(const Json& object, const char* key, const std::string& where) const;
    /// root[array][index], or an error naming `where` and the array size.
    const Json& Element(const char* array, uint64_t index, const std::string& where) const;

    /// The accessor's values as float [count, components]: float components exactly,
    /// integers as the glTF spec defines (normalised: c / max, signed clamped at -1), sparse
    /// substitution applied. The component type must be one of `allowed`, the type have
    /// `components`. expected_count < 0: the accessor must be stored in a bufferView (it
    /// sets the count); otherwise its count must equal expected_count (a missing bufferView
    /// then means zeros). `attribute` names it in errors.
    std::vector<float> DecodeAccessor(uint64_t index, const std::string& attribute, int components,
                                      const std::vector<Allowed>& allowed, int64_t expected_count);
    /// The bytes of bufferViews[index], checked against its buffer; `where` names the
    /// object that refers to it.
    Span BufferView(uint64_t index, const std::string& where) {
        return View(index, where, nullptr);
    }

private:
    void ParseGlb(ReadPointCloudReport& report);
    void CheckAssetAndExtensions();
    Span Buffer(uint64_t index, const std::string& where);
    Span View(uint64_t index, const std::string& where, uint64_t* stride);

    std::string filename_;
    MappedFile file_;
    Json root_;
    bool is_glb_ = false;
    std::optional<Span> bin_chunk_;
    std::vector<std::optional<Span>> buffers_;
    std::vector<std::vector<uint8_t>> decoded_;          // data-URI buffers
    std::vector<std::unique_ptr<MappedFile>> external_;  // .bin files
    uint64_t input_bytes_ = 0;
};

}  // namespace gltf
}  // namespace io
}  // namespace t
}  // namespace open3d
