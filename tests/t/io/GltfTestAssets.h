// Shared by the glTF tests (GltfFormatTest.cpp, GltfMalformedTest.cpp): glTF assets built byte
// by byte (JSON + one buffer, written as .gltf with a data URI or an external .bin, or as
// .glb), the minimal current-spec asset and its expected cloud, and the error check.
#pragma once

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "IoTestHelpers.h"
#include "open3d/core/Exception.h"
#include "open3d/t/io/GltfCommon.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {
namespace gltf_test {

using core::Open3DError;
using core::Tensor;
using geometry::PointCloud;
using Json = nlohmann::json;
namespace fs = std::filesystem;

inline constexpr int kFloat = 5126, kByte = 5120, kUByte = 5121, kShort = 5122, kUShort = 5123;
inline const std::string kP = "KHR_gaussian_splatting:";

inline std::vector<uint8_t> ReadBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

inline void WriteBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
}

template <typename T>
inline std::vector<uint8_t> Raw(const std::vector<T>& values) {
    std::vector<uint8_t> out(values.size() * sizeof(T));
    std::memcpy(out.data(), values.data(), out.size());
    return out;
}

// A test-local base64 encoder (RFC 4648), so the reader is not checked by its own encoder.
inline std::string Base64(const std::vector<uint8_t>& in) {
    static const char* abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < in.size(); i += 3) {
        uint32_t v = uint32_t(in[i]) << 16;
        if (i + 1 < in.size()) v |= uint32_t(in[i + 1]) << 8;
        if (i + 2 < in.size()) v |= in[i + 2];
        out += abc[v >> 18];
        out += abc[(v >> 12) & 63];
        out += i + 1 < in.size() ? abc[(v >> 6) & 63] : '=';
        out += i + 2 < in.size() ? abc[v & 63] : '=';
    }
    return out;
}

// A glTF asset assembled in the test: JSON and the bytes of its one buffer.
struct Asset {
    Json json;
    std::vector<uint8_t> bin;

    int AddView(const std::vector<uint8_t>& bytes, int stride = 0) {
        while (bin.size() % 4 != 0) bin.push_back(0);
        Json view = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes.size()}};
        if (stride > 0) view["byteStride"] = stride;
        bin.insert(bin.end(), bytes.begin(), bytes.end());
        json["bufferViews"].push_back(view);
        return int(json["bufferViews"].size()) - 1;
    }
    int AddAccessor(int view, int offset, int component, const char* type, int count,
                    bool normalized = false) {
        Json a = {{"componentType", component}, {"type", type}, {"count", count}};
        if (view >= 0) a["bufferView"] = view;
        if (offset > 0) a["byteOffset"] = offset;
        if (normalized) a["normalized"] = true;
        json["accessors"].push_back(a);
        return int(json["accessors"].size()) - 1;
    }
    int Add(const std::vector<uint8_t>& bytes, int component, const char* type, int count,
            bool normalized = false, int stride = 0) {
        return AddAccessor(AddView(bytes, stride), 0, component, type, count, normalized);
    }
    Json& Primitive() { return json["meshes"][0]["primitives"][0]; }
    Json& Attributes() { return Primitive()["attributes"]; }
    Json& AccessorOf(const std::string& attribute) {
        return json["accessors"][Attributes()[attribute].get<int>()];
    }

    // .gltf with the buffer as `uri`: "" for a base64 data URI, otherwise a file name beside it.
    std::string WriteGltf(const std::string& path, const std::string& uri = "") const {
        Json j = json;
        j["buffers"] = {{{"byteLength", bin.size()}}};
        if (uri.empty()) {
            j["buffers"][0]["uri"] = "data:application/octet-stream;base64," + Base64(bin);
        } else {
            j["buffers"][0]["uri"] = uri;
            std::string name;  // the test's uris percent-encode only spaces
            for (size_t k = 0; k < uri.size(); ++k) {
                const bool space = uri.compare(k, 3, "%20") == 0;
                name += space ? ' ' : uri[k];
                if (space) k += 2;
            }
            WriteBytes((fs::path(path).parent_path() / name).string(), bin);
        }
        const std::string text = j.dump(1);
        WriteBytes(path, std::vector<uint8_t>(text.begin(), text.end()));
        return path;
    }
    std::string WriteGlb(const std::string& path) const {
        Json j = json;
        j["buffers"] = {{{"byteLength", bin.size()}}};
        std::string text = j.dump();
        while (text.size() % 4 != 0) text += ' ';
        std::vector<uint8_t> b = bin;
        while (b.size() % 4 != 0) b.push_back(0);
        std::vector<uint8_t> out;
        const auto u32 = [&](uint32_t v) {
            for (int k = 0; k < 4; ++k) out.push_back(uint8_t(v >> (8 * k)));
        };
        u32(0x46546C67), u32(2), u32(uint32_t(12 + 8 + text.size() + 8 + b.size()));
        u32(uint32_t(text.size())), u32(0x4E4F534A);
        out.insert(out.end(), text.begin(), text.end());
        u32(uint32_t(b.size())), u32(0x004E4942);
        out.insert(out.end(), b.begin(), b.end());
        WriteBytes(path, out);
        return path;
    }
};

inline Json Skeleton() {
    return {{"asset", {{"version", "2.0"}}},
            {"extensionsUsed", {"KHR_gaussian_splatting"}},
            {"scene", 0},
            {"scenes", {{{"nodes", {0}}}}},
            {"nodes", {{{"mesh", 0}}}},
            {"meshes",
             {{{"primitives",
                {{{"attributes", Json::object()},
                  {"mode", 0},
                  {"extensions",
                   {{"KHR_gaussian_splatting",
                     {{"kernel", "ellipse"}, {"colorSpace", "srgb_rec709_display"}}}}}}}}}}},
            {"accessors", Json::array()},
            {"bufferViews", Json::array()}};
}

// The minimal current-spec asset: 3 splats, SH degree 1, every attribute float, no transform.
inline const std::vector<float> kPos = {1, 2, 3, -4, 5, -6, 0.5f, 0, -0.25f};
inline const std::vector<float> kRotXyzw = {0, 0, 0, 1, 0.5f, 0.5f, 0.5f, 0.5f, 0, 0.6f, 0, 0.8f};
inline const std::vector<float> kScale = {0.1f, 0.2f, 0.3f, 1, 2, 3, 0.01f, 0.01f, 0.5f};
inline const std::vector<float> kAlpha = {0.5f, 0.25f, 1.0f};
inline const std::vector<float> kDc = {0.1f, -0.2f, 0.3f, 1, 0, -1, 0.5f, 0.5f, 0.5f};
inline float Sh1(int coef, int splat, int c) { return 0.01f * float(coef * 9 + splat * 3 + c + 1); }

inline Asset MinimalAsset() {
    Asset a;
    a.json = Skeleton();
    Json& at = a.Attributes();
    at["POSITION"] = a.Add(Raw(kPos), kFloat, "VEC3", 3);
    a.json["accessors"][0]["min"] = {-4, 0, -6};
    a.json["accessors"][0]["max"] = {1, 5, 3};
    at[kP + "ROTATION"] = a.Add(Raw(kRotXyzw), kFloat, "VEC4", 3);
    at[kP + "SCALE"] = a.Add(Raw(kScale), kFloat, "VEC3", 3);
    at[kP + "OPACITY"] = a.Add(Raw(kAlpha), kFloat, "SCALAR", 3);
    at[kP + "SH_DEGREE_0_COEF_0"] = a.Add(Raw(kDc), kFloat, "VEC3", 3);
    for (int n = 0; n < 3; ++n) {
        std::vector<float> v;
        for (int i = 0; i < 3; ++i) {
            for (int c = 0; c < 3; ++c) v.push_back(Sh1(n, i, c));
        }
        at[kP + "SH_DEGREE_1_COEF_" + std::to_string(n)] = a.Add(Raw(v), kFloat, "VEC3", 3);
    }
    return a;
}

inline void ExpectMinimalValues(const PointCloud& cloud) {
    ASSERT_EQ(cloud.NumPoints(), 3);
    ASSERT_TRUE(cloud.IsGaussianSplat());
    EXPECT_EQ(cloud.GaussianSplatGetSHOrder(), 1);
    const float* p = cloud.GetPointPositions().Data<float>();
    const float* q = cloud.GetPointAttr("rot").Data<float>();
    const float* s = cloud.GetPointAttr("scale").Data<float>();
    const float* o = cloud.GetPointAttr("opacity").Data<float>();
    const float* dc = cloud.GetPointAttr("f_dc").Data<float>();
    const float* rest = cloud.GetPointAttr("f_rest").Data<float>();
    const float sign1[3] = {-1, -1, +1};  // Y_1,-1 ~ y and Y_1,0 ~ z change sign, Y_1,1 ~ x not
    for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(p[i * 3 + 0], kPos[i * 3 + 0]);  // RDF = (x, -y, -z) of glTF, exactly
        EXPECT_EQ(p[i * 3 + 1], -kPos[i * 3 + 1]);
        EXPECT_EQ(p[i * 3 + 2], -kPos[i * 3 + 2]);
        EXPECT_EQ(q[i * 4 + 0], kRotXyzw[i * 4 + 3]);  // (w, x, -y, -z)
        EXPECT_EQ(q[i * 4 + 1], kRotXyzw[i * 4 + 0]);
        EXPECT_EQ(q[i * 4 + 2], -kRotXyzw[i * 4 + 1]);
        EXPECT_EQ(q[i * 4 + 3], -kRotXyzw[i * 4 + 2]);
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(s[i * 3 + c], kScale[i * 3 + c]);
            EXPECT_EQ(dc[i * 3 + c], kDc[i * 3 + c]);
            for (int n = 0; n < 3; ++n)
                EXPECT_EQ(rest[(i * 3 + n) * 3 + c], sign1[n] * Sh1(n, i, c));
        }
    }
    EXPECT_EQ(o[0], 0.0f);                                // logit(0.5)
    EXPECT_FLOAT_EQ(o[1], float(std::log(0.25 / 0.75)));  // -1.0986123
    EXPECT_EQ(o[2], gltf::kOpaqueLogit);                  // alpha 1 -> 18
}

using io::ExpectReadError;  // ExpectReadError.h

}  // namespace gltf_test
}  // namespace io
}  // namespace t
}  // namespace open3d
