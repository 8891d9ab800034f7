// Internal to t/io: WebP images as SOG stores its attribute planes (RGBA8, lossless).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace open3d {
namespace t {
namespace io {

struct Rgba8Image {
    int width = 0;
    int height = 0;
    std::vector<uint8_t> rgba;  // width * height * 4, rows top to bottom
};

/// Decodes a WebP image to RGBA8; throws naming `what` when it is not a valid WebP or is
/// larger than max_pixels.
Rgba8Image DecodeWebp(const uint8_t* data, size_t size, const std::string& what,
                      int64_t max_pixels = int64_t(1) << 28);
/// Encodes RGBA8 as lossless WebP (exact: every byte, transparent pixels' colour included).
std::vector<uint8_t> EncodeWebpLossless(const Rgba8Image& image);

}  // namespace io
}  // namespace t
}  // namespace open3d
