// Internal to t/io: one splat primitive as the glTF reader holds it between reading
// (GltfFormat.cpp for KHR_gaussian_splatting, GltfSpz.cpp for the SPZ-compressed draft) and
// placing it in the scene (GltfFormat.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "open3d/t/io/GltfDocument.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {
namespace gltf {

// First in its node's glTF frame, then (SceneReader::Place) in the RDF world frame.
struct PrimitiveData {
    int64_t n = 0;
    int degree = 0;
    std::vector<float> positions;  // [n, 3]
    std::vector<float> rot;        // [n, 4] (w, x, y, z)
    std::vector<float> scale;      // [n, 3] linear
    std::vector<float> opacity;    // [n] logit
    std::vector<float> f_dc;       // [n, 3]
    std::vector<float> f_rest;     // [n, Nc, 3]
};

/// Reads a primitive whose `extensions` hold KHR_spz_gaussian_splats_compression
/// (`extension` is that object): checks the primitive and its attributes, decodes the SPZ of
/// the extension's bufferView and fills `out` in the primitive's glTF frame. `where` names
/// the primitive in errors ("mesh 0 primitive 1").
void ReadSpzPrimitive(GltfDocument& doc, const Json& primitive, const Json& extension,
                      const std::string& where, PrimitiveData& out, ReadPointCloudReport& report);

}  // namespace gltf
}  // namespace io
}  // namespace t
}  // namespace open3d
