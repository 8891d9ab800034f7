// GltfDocument.h: the glTF container (.gltf JSON, .glb chunks), buffers and accessors.
#include "open3d/t/io/GltfDocument.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/io/GltfCommon.h"

static_assert(std::endian::native == std::endian::little, "glTF buffers are little endian");

namespace open3d {
namespace t {
namespace io {
namespace gltf {
namespace {

namespace fs = std::filesystem;

// JSON integers above 2^53 cannot be exact in every JSON reader; offsets and counts stay below.
constexpr uint64_t kMaxJsonInteger = uint64_t(1) << 53;

int ComponentSize(int type) {
    switch (type) {
        case kComponentByte:
        case kComponentUnsignedByte:
            return 1;
        case kComponentShort:
        case kComponentUnsignedShort:
            return 2;
        case kComponentUnsignedInt:
        case kComponentFloat:
            return 4;
    }
    return 0;
}

std::string ComponentName(int type, bool normalized) {
    const char* names[] = {"signed byte", "unsigned byte", "signed short", "unsigned short",
                           "?",           "unsigned int",  "float"};
    const std::string name =
        type >= kComponentByte && type <= kComponentFloat && ComponentSize(type) > 0
            ? names[type - kComponentByte]
            : fmt::format("unknown ({})", type);
    return normalized ? name + " normalized" : name;
}

const char* TypeName(int components) {
    switch (components) {
        case 1:
            return "SCALAR";
        case 3:
            return "VEC3";
        case 4:
            return "VEC4";
    }
    return "?";
}

// One component as the glTF spec defines normalised integers (signed: max(c / MAX, -1)).
float ReadComponent(const uint8_t* p, int type, bool normalized) {
    switch (type) {
        case kComponentFloat: {
            float f;
            std::memcpy(&f, p, 4);
            return f;
        }
        case kComponentByte: {
            const int8_t v = static_cast<int8_t>(*p);
            return normalized ? float(std::max(v / 127.0, -1.0)) : float(v);
        }
        case kComponentUnsignedByte:
            return normalized ? float(*p / 255.0) : float(*p);
        case kComponentShort: {
            int16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? float(std::max(v / 32767.0, -1.0)) : float(v);
        }
        case kComponentUnsignedShort: {
            uint16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? float(v / 65535.0) : float(v);
        }
        default: {
            uint32_t v;
            std::memcpy(&v, p, 4);
            return float(v);
        }
    }
}

uint32_t ReadU32(const uint8_t* p) {
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

}  // namespace

// Arrays and objects are not printed: dump() recurses, and a hostile file may nest them
// thousands deep.
std::string BriefJson(const Json& v) {
    if (v.is_array()) return "an array";
    if (v.is_object()) return "an object";
    const std::string text = v.dump();
    return text.size() > 40 ? text.substr(0, 40) + "..." : text;
}

GltfDocument::GltfDocument(const std::string& filename, ReadPointCloudReport& report)
    : filename_(filename), file_(filename) {
    input_bytes_ = file_.size();
    Span json{file_.data(), file_.size()};
    if (file_.size() >= 4 && ReadU32(file_.data()) == kGlbMagic) {
        is_glb_ = true;
        ParseGlb(report);
        json = {file_.data() + 20, ReadU32(file_.data() + 12)};
    }
    try {
        root_ = Json::parse(json.data, json.data + json.size);
    } catch (const Json::exception& e) {
        Fail("invalid glTF JSON{}: {}", is_glb_ ? " in the GLB JSON chunk" : "", e.what());
    }
    if (!root_.is_object()) Fail("the glTF JSON is not an object");
    CheckAssetAndExtensions();
}

void GltfDocument::ParseGlb(ReadPointCloudReport& report) {
    const uint64_t size = file_.size();
    const uint8_t* p = file_.data();
    if (size < 12) Fail("GLB header needs 12 bytes, the file has {}", size);
    if (ReadU32(p + 4) != 2) Fail("GLB container version {}, expected 2", ReadU32(p + 4));
    const uint64_t length = ReadU32(p + 8);
    if (length > size) {
        Fail("GLB header declares {} bytes but the file has {} (truncated)", length, size);
    }
    if (length < size) {
        report.trailing_bytes = static_cast<int64_t>(size - length);
        core::LogWarning("'{}': {} bytes after the GLB length {} are ignored", filename_,
                         size - length, length);
    }
    uint64_t pos = 12;
    for (int chunk = 0; chunk < 2 && pos < length; ++chunk) {
        if (length - pos < 8) {
            Fail("GLB chunk {} at byte {}: {} bytes left, a chunk header needs 8", chunk, pos,
                 length - pos);
        }
        const uint64_t chunk_length = ReadU32(p + pos);
        const uint32_t type = ReadU32(p + pos + 4);
        const char* name = type == kChunkJson ? "JSON" : type == kChunkBin ? "BIN" : "unknown";
        if (chunk_length > length - pos - 8) {
            Fail("GLB chunk {} ({}) at byte {} declares {} bytes, past the GLB end at byte {}",
                 chunk, name, pos, chunk_length, length);
        }
        if (chunk == 0 && type != kChunkJson) {
            Fail("the first GLB chunk has type 0x{:08X}, not JSON (0x4E4F534A)", type);
        }
        if (chunk == 1 && type == kChunkBin) bin_chunk_ = Span{p + pos + 8, chunk_length};
        pos += 8 + chunk_length;  // chunks after BIN have unknown types: ignored, as required
    }
    if (pos == 12) Fail("GLB has no JSON chunk");
}

void GltfDocument::CheckAssetAndExtensions() {
    const Json* asset = Find(root_, "asset");
    if (asset == nullptr || !asset->is_object()) {
        Fail("no 'asset' object (every glTF has asset.version)");
    }
    const auto text = [&](const char* key) -> std::optional<std::string> {
        const Json* v = Find(*asset, key);
        if (v == nullptr) return std::nullopt;
        if (!v->is_string()) Fail("asset.{} is not a string", key);
        return v->get<std::string>();
    };
    const std::string version = text("version").value_or("");
    if (version.rfind("2.", 0) != 0) {
        Fail("asset.version is '{}': this reader reads glTF 2.x", version.substr(0, 40));
    }
    if (const auto min_version = text("minVersion"); min_version && *min_version != "2.0") {
        Fail("asset.minVersion is '{}': this reader implements glTF 2.0",
             min_version->substr(0, 40));
    }
    const Json* required = Find(root_, "extensionsRequired");
    if (required == nullptr) return;
    if (!required->is_array()) Fail("extensionsRequired is not an array");
    for (const Json& name : *required) {
        const std::string s = name.is_string() ? name.get<std::string>() : BriefJson(name);
        // Material and texture extensions do not touch splat data; quantised positions are
        // decoded like every normalised accessor; SPZ-compressed splats are decoded.
        if (s == kExtension || s == kSpzExtension || s == "KHR_mesh_quantization" ||
            s.rfind("KHR_materials_", 0) == 0 || s.rfind("KHR_texture_", 0) == 0) {
            continue;
        }
        Fail("requires the extension {}, which this reader does not implement{}", s.substr(0, 80),
             s.rfind("KHR_gaussian_splatting_compression", 0) == 0
                 ? " (compressed splats: write them out uncompressed with the tool that "
                   "made them)"
                 : "");
    }
}

const Json* GltfDocument::Find(const Json& object, const char* key) const {
    if (!object.is_object()) return nullptr;
    const auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
}

uint64_t GltfDocument::Uint(const Json& object, const char* key, const std::string& where,
                            std::optional<uint64_t> fallback) const {
    if (!object.is_object()) Fail("{} is not a JSON object", where);
    const Json* v = Find(object, key);
    if (v == nullptr) {
        if (!fallback) Fail("{} has no '{}'", where, key);
        return *fallback;
    }
    if (!v->is_number_unsigned()) {
        Fail("{}: '{}' is {}, not a non-negative integer", where, key, BriefJson(*v));
    }
    const uint64_t value = v->get<uint64_t>();
    if (value > kMaxJsonInteger) Fail("{}: '{}' = {} is out of range", where, key, value);
    return value;
}

double GltfDocument::Number(const Json& value, const std::string& where) const {
    if (!value.is_number() || !std::isfinite(value.get<double>())) {
        Fail("{}: {} is not a finite number", where, BriefJson(value));
    }
    return value.get<double>();
}

std::string GltfDocument::String(const Json& object, const char* key,
                                 const std::string& where) const {
    const Json* v = Find(object, key);
    if (v == nullptr) Fail("{} has no '{}' (required)", where, key);
    if (!v->is_string()) Fail("{}: '{}' is {}, not a string", where, key, BriefJson(*v));
    return v->get<std::string>();
}

const Json& GltfDocument::Element(const char* array, uint64_t index,
                                  const std::string& where) const {
    const Json* a = Find(root_, array);
    const size_t size = a != nullptr && a->is_array() ? a->size() : 0;
    if (index >= size) Fail("{} refers to {}[{}], but there are {}", where, array, index, size);
    return (*a)[index];
}

Span GltfDocument::Buffer(uint64_t index, const std::string& where) {
    const std::string what = fmt::format("buffer {}", index);
    const Json& buffer = Element("buffers", index, where);
    if (buffers_.size() <= index) buffers_.resize(index + 1);
    if (buffers_[index]) return *buffers_[index];
    const uint64_t byte_length = Uint(buffer, "byteLength", what);
    const Json* uri = Find(buffer, "uri");
    Span data;
    if (uri == nullptr) {
        if (index != 0 || !bin_chunk_) {
            Fail("{} has no uri and there is no GLB BIN chunk for it", what);
        }
        data = *bin_chunk_;
    } else {
        if (!uri->is_string()) Fail("{}: uri is not a string", what);
        const std::string s = uri->get<std::string>();
        std::string lower = s.substr(0, std::min<size_t>(s.find(','), 64));
        for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        if (lower.rfind("data:", 0) == 0) {
            const size_t comma = s.find(',');
            if (comma == std::string::npos) Fail("{}: the data URI has no ','", what);
            if (lower.size() < 12 || lower.compare(lower.size() - 7, 7, ";base64") != 0) {
                Fail(
                    "{}: the data URI '{}...' is not base64; glTF buffers in data URIs are "
                    "base64",
                    what, s.substr(0, std::min<size_t>(comma + 1, 48)));
            }
            decoded_.emplace_back();
            if (!Base64Decode(s.data() + comma + 1, s.size() - comma - 1, decoded_.back())) {
                Fail("{}: the data URI holds invalid base64 text", what);
            }
            data = {decoded_.back().data(), decoded_.back().size()};
        } else {
            // A relative path (percent-decoded) inside the .gltf's folder; no scheme, no
            // absolute path, no '..': a file must not make the reader open arbitrary paths.
            std::string path;
            for (size_t i = 0; i < s.size(); ++i) {
                if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(uint8_t(s[i + 1])) &&
                    std::isxdigit(uint8_t(s[i + 2]))) {
                    path += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
                    i += 2;
                } else {
                    path += s[i];
                }
            }
            const size_t colon = path.find(':'), slash = path.find('/');
            const fs::path relative(path);
            bool parent = false;
            for (const auto& part : relative) parent = parent || part == "..";
            if (path.empty() || path.find('\0') != std::string::npos || path[0] == '/' ||
                (colon != std::string::npos && colon < slash) || parent) {
                Fail(
                    "{}: uri '{}' is not a relative path inside the file's folder (URL "
                    "schemes, absolute paths and '..' are refused)",
                    what, s.substr(0, 200));
            }
            const fs::path full = fs::path(filename_).parent_path() / relative;
            std::error_code error;  // checked first: opening a FIFO would block
            if (!fs::is_regular_file(full, error)) {
                Fail("{} (uri '{}'): '{}' is not a regular file", what, s.substr(0, 200),
                     full.string());
            }
            try {
                external_.push_back(std::make_unique<MappedFile>(full.string()));
            } catch (const core::Open3DError& e) {
                Fail("{} (uri '{}'): {}", what, s.substr(0, 200), e.what());
            }
            data = {external_.back()->data(), external_.back()->size()};
            input_bytes_ += data.size;
        }
    }
    if (data.size < byte_length) {
        Fail("{} declares byteLength {} but its data has {} bytes", what, byte_length, data.size);
    }
    data.size = byte_length;
    buffers_[index] = data;
    return data;
}

Span GltfDocument::View(uint64_t index, const std::string& where, uint64_t* stride) {
    const std::string what = fmt::format("bufferView {}", index);
    const Json& view = Element("bufferViews", index, where);
    const uint64_t buffer_index = Uint(view, "buffer", what);
    const uint64_t offset = Uint(view, "byteOffset", what, 0);
    const uint64_t length = Uint(view, "byteLength", what);
    const Span buffer = Buffer(buffer_index, what);
    if (offset > buffer.size || length > buffer.size - offset) {
        Fail("{} (bytes {}..{} of buffer {}, for {}) is past the end of the buffer ({} bytes)",
             what, offset, offset + length, buffer_index, where, buffer.size);
    }
    if (stride != nullptr) {
        *stride = Uint(view, "byteStride", what, 0);
        if (*stride != 0 && (*stride < 4 || *stride > 252)) {
            Fail("{}: byteStride {} is outside 4..252", what, *stride);
        }
    }
    return {buffer.data + offset, length};
}

std::vector<float> GltfDocument::DecodeAccessor(uint64_t index, const std::string& attribute,
                                                int components, const std::vector<Allowed>& allowed,
                                                int64_t expected_count) {
    const std::string what = fmt::format("accessor {} ({})", index, attribute);
    const Json& accessor = Element("accessors", index, attribute);
    const uint64_t type = Uint(accessor, "componentType", what);
    const Json* normalized_json = Find(accessor, "normalized");
    const bool normalized =
        normalized_json != nullptr && normalized_json->is_boolean() && normalized_json->get<bool>();
    const std::string type_name = String(accessor, "type", what);
    if (type_name != TypeName(components)) {
        Fail("{} has type {}; {} needs {}", what, type_name, attribute, TypeName(components));
    }
    const bool ok = std::any_of(allowed.begin(), allowed.end(), [&](const Allowed& a) {
        return uint64_t(a.component_type) == type && a.normalized == normalized;
    });
    if (!ok) {
        std::vector<std::string> names;
        for (const Allowed& a : allowed)
            names.push_back(ComponentName(a.component_type, a.normalized));
        Fail("{} has componentType {}; {} allows {}", what,
             ComponentName(static_cast<int>(std::min<uint64_t>(type, 1 << 30)), normalized),
             attribute, fmt::join(names, ", "));
    }
    const uint64_t count = Uint(accessor, "count", what);
    if (count == 0) Fail("{} has count 0", what);
    if (expected_count >= 0 && count != uint64_t(expected_count)) {
        Fail("{} has count {} but POSITION has {}: every attribute needs one value per splat", what,
             count, expected_count);
    }
    const int size = ComponentSize(static_cast<int>(type));
    const uint64_t element = uint64_t(size) * components;
    const Json* view_json = Find(accessor, "bufferView");
    if (view_json == nullptr && expected_count < 0) {
        Fail("{} has no bufferView: the splat positions must be stored", what);
    }
    std::vector<float> out;
    if (view_json != nullptr) {
        uint64_t stride = 0;
        const Span view = View(Uint(accessor, "bufferView", what), what, &stride);
        if (stride == 0) stride = element;
        if (stride < element) Fail("{}: byteStride {} < element size {}", what, stride, element);
        const uint64_t offset = Uint(accessor, "byteOffset", what, 0);
        const uint64_t need = offset + stride * (count - 1) + element;  // < 2^62: no overflow
        if (need > view.size) {
            Fail(
                "{} needs {} bytes (offset {}, {} elements, stride {}) but its bufferView has "
                "{}: the accessor is past the end of its buffer",
                what, need, offset, count, stride, view.size);
        }
        out.resize(count * components);
        const uint8_t* base = view.data + offset;
        if (type == kComponentFloat && stride == element) {
            std::memcpy(out.data(), base, count * element);
        } else {
            core::ParallelFor(int64_t(count), [&](int64_t i) {
                for (int c = 0; c < components; ++c) {
                    out[i * components + c] =
                        ReadComponent(base + i * stride + c * size, int(type), normalized);
                }
            });
        }
    } else {
        out.assign(count * components, 0.0f);  // count equals POSITION's, which is stored
    }
    if (const Json* sparse = Find(accessor, "sparse")) {
        const std::string sw = what + " sparse";
        const uint64_t k = Uint(*sparse, "count", sw);
        if (k == 0 || k > count) Fail("{}: count {} is not in 1..{}", sw, k, count);
        const Json* indices = Find(*sparse, "indices");
        const Json* values = Find(*sparse, "values");
        if (indices == nullptr || values == nullptr) Fail("{} needs indices and values", sw);
        const uint64_t index_type = Uint(*indices, "componentType", sw + " indices");
        const int index_size = index_type == kComponentUnsignedByte    ? 1
                               : index_type == kComponentUnsignedShort ? 2
                               : index_type == kComponentUnsignedInt   ? 4
                                                                       : 0;
        if (index_size == 0) Fail("{}: index componentType {} is not unsigned", sw, index_type);
        const Span iv = View(Uint(*indices, "bufferView", sw), sw, nullptr);
        const Span vv = View(Uint(*values, "bufferView", sw), sw, nullptr);
        const uint64_t io = Uint(*indices, "byteOffset", sw, 0);
        const uint64_t vo = Uint(*values, "byteOffset", sw, 0);
        if (io > iv.size || k * index_size > iv.size - io || vo > vv.size ||
            k * element > vv.size - vo) {
            Fail("{}: {} indices or values are past the end of their bufferViews", sw, k);
        }
        uint64_t previous = 0;
        for (uint64_t j = 0; j < k; ++j) {
            const uint8_t* p = iv.data + io + j * index_size;
            const uint64_t i = index_size == 1   ? *p
                               : index_size == 2 ? ReadComponent(p, kComponentUnsignedShort, false)
                                                 : ReadU32(p);
            if (i >= count || (j > 0 && i <= previous)) {
                Fail("{}: index {} (entry {}) is out of range or not increasing", sw, i, j);
            }
            previous = i;
            for (int c = 0; c < components; ++c) {
                out[i * components + c] =
                    ReadComponent(vv.data + vo + j * element + c * size, int(type), normalized);
            }
        }
    }
    return out;
}

}  // namespace gltf
}  // namespace io
}  // namespace t
}  // namespace open3d
