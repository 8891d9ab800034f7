// The helpers of GltfCommon.h: SH attribute names, the opacity encoding, base64.
#include "open3d/t/io/GltfCommon.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace open3d {
namespace t {
namespace io {
namespace gltf {

std::string ShAttributeName(int degree, int coefficient) {
    return fmt::format("{}SH_DEGREE_{}_COEF_{}", kAttributePrefix, degree, coefficient);
}

float DecodeOpacity(float alpha) {
    if (alpha >= 1.0f) return kOpaqueLogit;
    if (alpha <= 0.0f) return kTransparentLogit;
    const double a = alpha;
    return static_cast<float>(std::log(a) - std::log1p(-a));
}

float EncodeOpacity(float logit) {
    const float nearest = static_cast<float>(1.0 / (1.0 + std::exp(-double(logit))));
    if (!std::isfinite(logit) || DecodeOpacity(nearest) == logit) return nearest;
    float down = nearest, up = nearest;
    for (int step = 0; step < 16; ++step) {
        down = std::nextafter(down, 0.0f);
        up = std::min(std::nextafter(up, 2.0f), 1.0f);
        if (DecodeOpacity(down) == logit) return down;
        if (DecodeOpacity(up) == logit) return up;
    }
    return nearest;
}

namespace {
constexpr char kBase64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
}

std::string Base64Encode(const uint8_t* data, size_t size) {
    std::string out;
    out.reserve((size + 2) / 3 * 4);
    for (size_t i = 0; i < size; i += 3) {
        const uint32_t b0 = data[i], b1 = i + 1 < size ? data[i + 1] : 0,
                       b2 = i + 2 < size ? data[i + 2] : 0;
        const uint32_t v = (b0 << 16) | (b1 << 8) | b2;
        out += kBase64[(v >> 18) & 63];
        out += kBase64[(v >> 12) & 63];
        out += i + 1 < size ? kBase64[(v >> 6) & 63] : '=';
        out += i + 2 < size ? kBase64[v & 63] : '=';
    }
    return out;
}

bool Base64Decode(const char* text, size_t size, std::vector<uint8_t>& out) {
    int8_t value[256];
    std::fill(std::begin(value), std::end(value), int8_t(-1));
    for (int k = 0; k < 64; ++k) value[static_cast<uint8_t>(kBase64[k])] = static_cast<int8_t>(k);
    size_t padding = 0;
    while (padding < 2 && size > padding && text[size - 1 - padding] == '=') ++padding;
    if (padding > 0 && size % 4 != 0) return false;
    const size_t digits = size - padding;
    if (digits % 4 == 1) return false;
    out.clear();
    out.reserve(digits / 4 * 3 + 2);
    uint32_t acc = 0;
    int bits = 0;
    for (size_t i = 0; i < digits; ++i) {
        const int v = value[static_cast<uint8_t>(text[i])];
        if (v < 0) return false;
        acc = (acc << 6) | uint32_t(v);
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out.push_back(static_cast<uint8_t>(acc >> bits));
            acc &= (1u << bits) - 1;
        }
    }
    return acc == 0;  // the unused low bits of the last digit must be zero (canonical text)
}

}  // namespace gltf
}  // namespace io
}  // namespace t
}  // namespace open3d
