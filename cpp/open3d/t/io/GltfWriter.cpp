// glTF 2.0 KHR_gaussian_splatting writer: a .glb (JSON chunk + BIN chunk) or a .gltf with one
// base64 data-URI buffer. One node without a transform, one mesh, one POINTS primitive; every
// attribute float32 in its own tightly packed bufferView; kernel "ellipse", colorSpace
// "srgb_rec709_display". The cloud's RDF axes become glTF's by the exact sign flips of
// GltfCommon.h, so everything but opacity reads back bit for bit (opacity: EncodeOpacity).

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/GltfCommon.h"
#include "open3d/t/io/SplatColumns.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using namespace gltf;
using OrderedJson = nlohmann::ordered_json;

constexpr int kArrayBuffer = 34962;  // bufferView.target for vertex attributes

void AppendU32(std::vector<uint8_t>& out, uint32_t v) {
    const uint8_t bytes[4] = {uint8_t(v), uint8_t(v >> 8), uint8_t(v >> 16), uint8_t(v >> 24)};
    out.insert(out.end(), bytes, bytes + 4);
}

}  // namespace

void WriteGltf(const std::string& filename, const geometry::PointCloud& cloud, bool binary) {
    if (!cloud.IsGaussianSplat()) {
        core::ThrowError(
            "Cannot write '{}': KHR_gaussian_splatting needs a Gaussian splat cloud (scale, "
            "rot, opacity, f_dc)",
            filename);
    }
    const geometry::GaussianSplatArrays a = cloud.GetGaussianSplatArrays();
    const int64_t n = a.num_points;
    const int nc = a.num_rest;
    if (n == 0)
        core::ThrowError("Cannot write '{}': glTF accessors need at least one splat", filename);
    for (int64_t k = 0; k < n * 3; ++k) {
        if (!std::isfinite(a.positions[k])) {
            core::ThrowError("Cannot write '{}': splat {} has a non-finite position", filename,
                             k / 3);
        }
        if (!(a.scale[k] >= 0.0f)) {
            core::ThrowError("Cannot write '{}': splat {} has scale {} (glTF needs scales >= 0)",
                             filename, k / 3, a.scale[k]);
        }
    }
    for (const auto& name : cloud.GetPointAttrNames()) {
        if (name != "positions" && name != "scale" && name != "rot" && name != "opacity" &&
            name != "f_dc" && name != "f_rest") {
            core::LogWarning("'{}': attribute '{}' is not written to glTF", filename, name);
        }
    }

    // Attribute blocks, in file order: name, components, values [n, components] in glTF axes.
    struct Block {
        std::string name;
        int components;
        std::vector<float> values;
    };
    std::vector<Block> blocks;
    blocks.push_back({"POSITION", 3, std::vector<float>(n * 3)});
    blocks.push_back({std::string(kAttributePrefix) + "ROTATION", 4, std::vector<float>(n * 4)});
    blocks.push_back(
        {std::string(kAttributePrefix) + "SCALE", 3, std::vector<float>(a.scale, a.scale + n * 3)});
    blocks.push_back({std::string(kAttributePrefix) + "OPACITY", 1, std::vector<float>(n)});
    blocks.push_back({ShAttributeName(0, 0), 3, std::vector<float>(a.f_dc, a.f_dc + n * 3)});
    for (int k = 0; k < nc; ++k) {
        const int l = static_cast<int>(std::sqrt(double(k + 1)));
        blocks.push_back({ShAttributeName(l, k + 1 - l * l), 3, std::vector<float>(n * 3)});
    }
    std::vector<uint8_t> zero_rotation(n, 0);
    core::ParallelFor(n, [&](int64_t i) {
        const float* p = a.positions + i * 3;
        float* position = &blocks[0].values[i * 3];
        position[0] = p[0], position[1] = -p[1], position[2] = -p[2];
        // Unit quaternions as FinalizeColumns leaves them (kept when within 2^-20 of unit).
        const float* q = a.rot + i * 4;
        double w = q[0], x = q[1], y = q[2], z = q[3];
        const double n2 = w * w + x * x + y * y + z * z;
        if (n2 == 0.0) zero_rotation[i] = 1;
        float out[4] = {q[1], q[2], q[3], q[0]};  // x, y, z, w
        if (n2 > 0.0 && std::abs(n2 - 1.0) > 0x1p-20) {
            const double inv = 1.0 / std::sqrt(n2);
            out[0] = float(x * inv), out[1] = float(y * inv), out[2] = float(z * inv);
            out[3] = float(w * inv);
        }
        float* rotation = &blocks[1].values[i * 4];
        rotation[0] = out[0], rotation[1] = -out[1], rotation[2] = -out[2], rotation[3] = out[3];
        blocks[3].values[i] = EncodeOpacity(a.opacity[i]);
        for (int k = 0; k < nc; ++k) {
            for (int c = 0; c < 3; ++c) {
                blocks[5 + k].values[i * 3 + c] = a.f_rest[(i * nc + k) * 3 + c] * kShSignRdf[k];
            }
        }
    });
    for (int64_t i = 0; i < n; ++i) {
        if (zero_rotation[i]) {
            core::ThrowError("Cannot write '{}': splat {} has a zero rotation quaternion", filename,
                             i);
        }
    }

    OrderedJson attributes = OrderedJson::object(), accessors = OrderedJson::array(),
                views = OrderedJson::array();
    std::vector<uint8_t> bin;
    for (size_t b = 0; b < blocks.size(); ++b) {
        const Block& block = blocks[b];
        const size_t bytes = block.values.size() * sizeof(float);
        OrderedJson accessor = {{"bufferView", b},
                                {"componentType", kComponentFloat},
                                {"count", n},
                                {"type", block.components == 1   ? "SCALAR"
                                         : block.components == 3 ? "VEC3"
                                                                 : "VEC4"}};
        if (b == 0) {  // glTF requires POSITION bounds
            float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
            for (int64_t i = 0; i < n; ++i) {
                for (int c = 0; c < 3; ++c) {
                    lo[c] = std::min(lo[c], block.values[i * 3 + c]);
                    hi[c] = std::max(hi[c], block.values[i * 3 + c]);
                }
            }
            accessor["min"] = {double(lo[0]), double(lo[1]), double(lo[2])};
            accessor["max"] = {double(hi[0]), double(hi[1]), double(hi[2])};
        }
        accessors.push_back(accessor);
        views.push_back({{"buffer", 0},
                         {"byteOffset", bin.size()},
                         {"byteLength", bytes},
                         {"target", kArrayBuffer}});
        attributes[block.name] = b;
        const auto* raw = reinterpret_cast<const uint8_t*>(block.values.data());
        bin.insert(bin.end(), raw, raw + bytes);
    }
    OrderedJson buffer = {{"byteLength", bin.size()}};
    if (!binary) {
        buffer["uri"] =
            "data:application/octet-stream;base64," + Base64Encode(bin.data(), bin.size());
    }
    const OrderedJson root = {
        {"asset", {{"version", "2.0"}, {"generator", "Open3D t::io::WritePointCloud"}}},
        {"extensionsUsed", {kExtension}},
        {"scene", 0},
        {"scenes", {{{"nodes", {0}}}}},
        {"nodes", {{{"mesh", 0}}}},
        {"meshes",
         {{{"primitives",
            {{{"attributes", attributes},
              {"mode", 0},
              {"extensions",
               {{kExtension,
                 {{"kernel", "ellipse"}, {"colorSpace", "srgb_rec709_display"}}}}}}}}}}},
        {"accessors", accessors},
        {"bufferViews", views},
        {"buffers", {buffer}}};
    std::string json = root.dump(binary ? -1 : 1);
    if (!binary) {
        json += '\n';
        WriteFileBytes(filename, std::vector<uint8_t>(json.begin(), json.end()));
        return;
    }
    while (json.size() % 4 != 0) json += ' ';  // the JSON chunk is padded with spaces
    while (bin.size() % 4 != 0) bin.push_back(0);
    const uint64_t total = 12 + 8 + json.size() + 8 + bin.size();
    if (total > UINT32_MAX) {
        core::ThrowError(
            "Cannot write '{}': {} bytes exceed the 4 GiB limit of .glb; write .ply "
            "or .spz",
            filename, total);
    }
    std::vector<uint8_t> out;
    out.reserve(total);
    AppendU32(out, kGlbMagic);
    AppendU32(out, 2);
    AppendU32(out, uint32_t(total));
    AppendU32(out, uint32_t(json.size()));
    AppendU32(out, kChunkJson);
    out.insert(out.end(), json.begin(), json.end());
    AppendU32(out, uint32_t(bin.size()));
    AppendU32(out, kChunkBin);
    out.insert(out.end(), bin.begin(), bin.end());
    WriteFileBytes(filename, out);
}

}  // namespace io
}  // namespace t
}  // namespace open3d
