// Internal to t/io: what the glTF KHR_gaussian_splatting reader (GltfFormat.cpp) and writer
// (GltfWriter.cpp) share: attribute names, the glTF <-> RDF axis change, the opacity
// encoding, base64.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace open3d {
namespace t {
namespace io {
namespace gltf {

inline constexpr const char* kExtension = "KHR_gaussian_splatting";
inline constexpr const char* kAttributePrefix = "KHR_gaussian_splatting:";
/// The draft that stores a primitive's splats as one SPZ blob (CesiumGS/glTF branch
/// draft-spz-splat-compression; read by GltfSpz.cpp).
inline constexpr const char* kSpzExtension = "KHR_spz_gaussian_splats_compression";

inline constexpr uint32_t kGlbMagic = 0x46546C67;   // "glTF"
inline constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
inline constexpr uint32_t kChunkBin = 0x004E4942;   // "BIN\0"
inline constexpr int kComponentFloat = 5126;
inline constexpr int kComponentByte = 5120;
inline constexpr int kComponentUnsignedByte = 5121;
inline constexpr int kComponentShort = 5122;
inline constexpr int kComponentUnsignedShort = 5123;
inline constexpr int kComponentUnsignedInt = 5125;

/// "KHR_gaussian_splatting:SH_DEGREE_<l>_COEF_<n>", n = m + l in 0..2l.
std::string ShAttributeName(int degree, int coefficient);

/// glTF is right-handed with +Y up and the asset's front facing +Z (a viewer in front of it
/// sees x right, y up, z towards them); 3DGS / OpenCV is x right, y down, z forward. The
/// change is the 180 degree rotation about x, C = diag(1, -1, -1), its own inverse:
/// positions (x, -y, -z), quaternions (w, x, -y, -z) (C R_q C, same covariance), and the
/// SH coefficient of basis j = 1..15 times the sign of Y_j(x, -y, -z) / Y_j(x, y, z): -1
/// where the basis polynomial is odd in (y, z). All exact (sign flips only).
inline constexpr std::array<float, 15> kShSignRdf = {
    -1, -1, +1,                  // l = 1: y, z, x
    -1, +1, +1, -1, +1,          // l = 2: xy, yz, 2z^2-x^2-y^2, xz, x^2-y^2
    -1, +1, -1, -1, +1, -1, +1,  // l = 3: y(3x^2-y^2), xyz, y(..), z(..), x(..), z(..), x(..)
};

/// The spec stores opacity as a linear alpha in [0, 1]; clouds hold the logit. Alpha 1 and
/// 0 map to finite logits whose sigmoid rounds back to 1.0f and 0.0f.
inline constexpr float kOpaqueLogit = 18.0f;
inline constexpr float kTransparentLogit = -110.0f;
/// logit(alpha) in double, rounded once; alpha outside (0, 1) gives the two limits above.
float DecodeOpacity(float alpha);
/// The float alpha whose DecodeOpacity is exactly `logit` when one exists within a few ulps
/// of sigmoid(logit), else the nearest float to sigmoid(logit).
float EncodeOpacity(float logit);

/// Standard base64 with padding.
std::string Base64Encode(const uint8_t* data, size_t size);
/// Strict base64 (standard alphabet, '=' padding optional, no whitespace); false on any
/// other character or a bad length.
bool Base64Decode(const char* text, size_t size, std::vector<uint8_t>& out);

}  // namespace gltf
}  // namespace io
}  // namespace t
}  // namespace open3d
