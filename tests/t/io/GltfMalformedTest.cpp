// The glTF reader on malformed input: every error names the file and the glTF object at fault
// (accessor and attribute, bufferView, buffer, GLB chunk, node), and leaves the cloud as it was.
#include <gtest/gtest.h>

#include "GltfTestAssets.h"
#include "TestUtility.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using namespace gltf_test;

// Malformed input: each error names the file and the glTF object at fault.
TEST(GltfFormat, MalformedAccessorsAndAttributes) {
    const std::string dir = tests::TempDir();
    const auto variant = [&](const std::string& name, auto edit) {
        Asset a = MinimalAsset();
        edit(a);
        return a.WriteGltf(dir + "/" + name + ".gltf");
    };
    const std::string scale = kP + "SCALE";
    const std::string scale_acc =
        "accessor " + std::to_string(MinimalAsset().Attributes()[scale].get<int>());
    ExpectReadError(
        variant("past_buffer", [&](Asset& a) { a.AccessorOf(scale)["byteOffset"] = 8; }),
        {scale_acc + " (" + scale + ")", "past the end"});
    ExpectReadError(
        variant("view_index", [&](Asset& a) { a.AccessorOf(kP + "ROTATION")["bufferView"] = 99; }),
        {kP + "ROTATION", "bufferViews[99]"});
    ExpectReadError(variant("view_past_buffer",
                            [&](Asset& a) { a.json["bufferViews"][1]["byteLength"] = 100000; }),
                    {"bufferView 1", "past the end of the buffer", kP + "ROTATION"});
    ExpectReadError(variant("count", [&](Asset& a) { a.AccessorOf(kP + "OPACITY")["count"] = 2; }),
                    {kP + "OPACITY", "count 2", "POSITION has 3"});
    ExpectReadError(variant("missing", [&](Asset& a) { a.Attributes().erase(kP + "OPACITY"); }),
                    {"no " + kP + "OPACITY attribute"});
    ExpectReadError(variant("sh_type",
                            [&](Asset& a) {
                                a.AccessorOf(kP + "SH_DEGREE_0_COEF_0")["componentType"] = kUShort;
                            }),
                    {kP + "SH_DEGREE_0_COEF_0", "unsigned short", "allows float"});
    ExpectReadError(variant("rot_type",
                            [&](Asset& a) {
                                a.AccessorOf(kP + "ROTATION")["componentType"] = kUByte;
                                a.AccessorOf(kP + "ROTATION")["normalized"] = true;
                            }),
                    {kP + "ROTATION", "unsigned byte normalized",
                     "allows float, signed byte normalized, signed short normalized"});
    ExpectReadError(
        variant("rot_vec3", [&](Asset& a) { a.AccessorOf(kP + "ROTATION")["type"] = "VEC3"; }),
        {kP + "ROTATION", "type VEC3", "needs VEC4"});
    ExpectReadError(
        variant("partial_sh", [&](Asset& a) { a.Attributes().erase(kP + "SH_DEGREE_1_COEF_1"); }),
        {"SH degree 1 is partly defined", "SH_DEGREE_1_COEF_1"});
    ExpectReadError(
        variant("kernel",
                [&](Asset& a) {
                    a.Primitive()["extensions"]["KHR_gaussian_splatting"].erase("kernel");
                }),
        {"no 'kernel'"});
    ExpectReadError(variant("mode", [&](Asset& a) { a.Primitive().erase("mode"); }),
                    {"mesh 0 primitive 0", "mode 4", "POINTS"});
    ExpectReadError(variant("negative_scale",
                            [&](Asset& a) {
                                std::vector<float> s = kScale;
                                s[4] = -2;
                                a.Attributes()[kP + "SCALE"] = a.Add(Raw(s), kFloat, "VEC3", 3);
                            }),
                    {scale, "splat 1", "negative"});
    ExpectReadError(variant("no_splats", [&](Asset& a) { a.Primitive().erase("extensions"); }),
                    {"no mesh primitive", "KHR_gaussian_splatting"});
    ExpectReadError(
        variant("required_ext",
                [&](Asset& a) {
                    a.json["extensionsRequired"] = {"KHR_gaussian_splatting_compression_spz_2"};
                }),
        {"requires the extension KHR_gaussian_splatting_compression_spz_2"});
    ExpectReadError(variant("sheared_node",
                            [&](Asset& a) {
                                a.json["nodes"][0]["matrix"] = {1, 0, 0, 0, 0.5, 1, 0, 0,
                                                                0, 0, 1, 0, 0,   0, 0, 1};
                            }),
                    {"mesh 0 primitive 0 (node 0)", "not a rotation times a positive scale"});
    ExpectReadError(variant("mirror_node",
                            [&](Asset& a) {
                                a.json["nodes"][0]["scale"] = {-1, -1, -1};
                            }),
                    {"not a rotation times a positive scale", "det -1"});
    ExpectReadError(variant("cycle",
                            [&](Asset& a) {
                                a.json["nodes"][0]["children"] = {1};
                                a.json["nodes"].push_back({{"children", {0}}});
                            }),
                    {"node 0 is reached twice"});
    ExpectReadError(variant("version", [&](Asset& a) { a.json["asset"]["version"] = "1.0"; }),
                    {"asset.version is '1.0'"});
}

TEST(GltfFormat, MalformedBuffersAndUris) {
    const std::string dir = tests::TempDir();
    const Asset asset = MinimalAsset();
    const std::string path = asset.WriteGltf(dir + "/ok.gltf");
    const auto with_uri = [&](const std::string& name, const std::string& uri) {
        Json j = Json::parse(ReadBytes(path));
        j["buffers"][0]["uri"] = uri;
        const std::string text = j.dump();
        WriteBytes(dir + "/" + name, std::vector<uint8_t>(text.begin(), text.end()));
        return dir + "/" + name;
    };
    ExpectReadError(with_uri("plain_data.gltf", "data:application/octet-stream,AAAA"),
                    {"buffer 0", "not base64"});
    ExpectReadError(with_uri("bad_base64.gltf", "data:application/octet-stream;base64,AA@A"),
                    {"buffer 0", "invalid base64"});
    ExpectReadError(with_uri("short_base64.gltf", "data:application/octet-stream;base64,AAAA"),
                    {"buffer 0", "byteLength", "has 3 bytes"});
    ExpectReadError(with_uri("missing_bin.gltf", "nothere.bin"), {"buffer 0", "nothere.bin"});
    ExpectReadError(with_uri("parent.gltf", "../ok.bin"), {"buffer 0", "'..'"});
    ExpectReadError(with_uri("absolute.gltf", "/etc/hostname"), {"buffer 0", "absolute"});
    ExpectReadError(with_uri("scheme.gltf", "https://example.com/a.bin"), {"buffer 0", "schemes"});
    WriteBytes(dir + "/truncated.json.gltf", std::vector<uint8_t>{'{', '"', 'a'});
    ExpectReadError(dir + "/truncated.json.gltf", {"invalid glTF JSON"});
    WriteBytes(dir + "/not_gltf.gltf", std::vector<uint8_t>{'{', '}'});
    ExpectReadError(dir + "/not_gltf.gltf", {"no 'asset' object"});
}

TEST(GltfFormat, MalformedGlbContainer) {
    const std::string dir = tests::TempDir();
    const std::vector<uint8_t> good = ReadBytes(MinimalAsset().WriteGlb(dir + "/good.glb"));
    uint32_t json_length;
    std::memcpy(&json_length, &good[12], 4);
    const size_t bin_header = 20 + json_length;
    const auto variant = [&](const std::string& name, auto edit) {
        std::vector<uint8_t> b = good;
        edit(b);
        WriteBytes(dir + "/" + name, b);
        return dir + "/" + name;
    };
    const auto put = [](std::vector<uint8_t>& b, size_t at, uint32_t v) {
        std::memcpy(&b[at], &v, 4);
    };
    ExpectReadError(variant("length.glb", [&](auto& b) { put(b, 8, uint32_t(b.size() + 4)); }),
                    {"GLB header declares", "truncated"});
    ExpectReadError(variant("json_chunk.glb", [&](auto& b) { put(b, 12, uint32_t(b.size())); }),
                    {"GLB chunk 0 (JSON)", "past the GLB end"});
    ExpectReadError(
        variant("bin_chunk.glb", [&](auto& b) { put(b, bin_header, uint32_t(b.size())); }),
        {"GLB chunk 1 (BIN)", "past the GLB end"});
    ExpectReadError(variant("bin_short.glb",
                            [&](auto& b) {
                                b.resize(b.size() - 8);  // BIN chunk shorter than the buffer
                                put(b, 8, uint32_t(b.size()));
                                put(b, bin_header, uint32_t(b.size() - bin_header - 8));
                            }),
                    {"buffer 0 declares byteLength"});
    ExpectReadError(variant("cut.glb", [&](auto& b) { b.resize(bin_header + 4); }),
                    {"GLB header declares"});
    ExpectReadError(variant("version.glb", [&](auto& b) { put(b, 4, 1); }),
                    {"GLB container version 1"});
    ExpectReadError(variant("first_chunk.glb", [&](auto& b) { put(b, 16, 0x004E4942); }),
                    {"first GLB chunk", "not JSON"});
    ExpectReadError(variant("tiny.glb", [&](auto& b) { b.resize(10); }), {"12 bytes"});
    // Trailing bytes after the declared length are reported and ignored.
    const std::string trailing =
        variant("trailing.glb", [&](auto& b) { b.resize(b.size() + 5, 0xAB); });
    PointCloud cloud;
    EXPECT_EQ(ReadPointCloud(trailing, cloud).trailing_bytes, 5);
    ExpectMinimalValues(cloud);
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
