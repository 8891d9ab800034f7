// Assembling SPZ files by hand, as the spec lays them out, for the SPZ tests
// (SpzFormatTest.cpp, SpzFormatFilesTest.cpp).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "IoTestHelpers.h"
#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/t/geometry/SHRotation.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/ByteCodecs.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {
namespace spz_test {

using core::Tensor;
using geometry::PointCloud;
using Bytes = std::vector<uint8_t>;

// ---- assembling SPZ files by hand, as the spec lays them out ----

inline uint32_t GetU32(const uint8_t* p) {
    return p[0] | p[1] << 8 | p[2] << 16 | uint32_t(p[3]) << 24;
}
inline uint64_t GetU64(const uint8_t* p) { return GetU32(p) | uint64_t(GetU32(p + 4)) << 32; }

struct RawSpz {
    uint32_t version = 4;
    uint32_t n = 0;
    uint8_t degree = 0, fractional_bits = 12, flags = 0;
    std::array<Bytes, 6> streams;  // positions, alphas, colours, scales, rotations, SH
    Bytes extensions;              // records; v4: before the TOC, v1-3: after the arrays
};

inline Bytes LegacyBytes(const RawSpz& r, bool gzip = true) {
    Bytes b;
    tests::AppendU32(b, 0x5053474e);
    tests::AppendU32(b, r.version);
    tests::AppendU32(b, r.n);
    b.insert(b.end(), {r.degree, r.fractional_bits, r.flags, 0});
    for (const Bytes& s : r.streams) b.insert(b.end(), s.begin(), s.end());
    b.insert(b.end(), r.extensions.begin(), r.extensions.end());
    return gzip ? GzipBytes(b.data(), b.size()) : b;
}

inline Bytes V4Bytes(const RawSpz& r) {
    std::vector<Bytes> chunks;
    std::vector<uint64_t> sizes;
    for (const Bytes& s : r.streams) {
        if (s.empty()) continue;
        chunks.push_back(ZstdCompressBytes(s.data(), s.size()));
        sizes.push_back(s.size());
    }
    Bytes b;
    tests::AppendU32(b, 0x5053474e);
    tests::AppendU32(b, r.version);
    tests::AppendU32(b, r.n);
    b.insert(b.end(), {r.degree, r.fractional_bits, r.flags, uint8_t(chunks.size())});
    tests::AppendU32(b, uint32_t(32 + r.extensions.size()));
    b.resize(32, 0);
    b.insert(b.end(), r.extensions.begin(), r.extensions.end());
    for (size_t i = 0; i < chunks.size(); ++i) {
        tests::AppendU64(b, chunks[i].size());
        tests::AppendU64(b, sizes[i]);
    }
    for (const Bytes& c : chunks) b.insert(b.end(), c.begin(), c.end());
    return b;
}

inline void WriteBytes(const std::string& path, const Bytes& bytes) {
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}
inline Bytes ReadBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return Bytes(std::istreambuf_iterator<char>(in), {});
}

/// The decompressed streams of a v4 file, read straight from its TOC.
inline std::vector<Bytes> V4Streams(const Bytes& file) {
    std::vector<Bytes> out;
    const uint32_t toc = GetU32(&file[16]);
    size_t offset = toc + file[15] * 16;
    for (int s = 0; s < file[15]; ++s) {
        const uint64_t compressed = GetU64(&file[toc + s * 16]);
        const uint64_t size = GetU64(&file[toc + s * 16 + 8]);
        out.push_back(ZstdDecompressBytes(&file[offset], compressed, size, "test"));
        offset += compressed;
    }
    return out;
}

// 3 x 24-bit fixed point, little endian.
inline void PutFixed(Bytes& b, std::array<int32_t, 3> v) {
    for (int32_t x : v) {
        for (int i = 0; i < 3; ++i) b.push_back(uint8_t(uint32_t(x) >> (8 * i)));
    }
}

inline const float* F(const PointCloud& c, const char* name) {
    return c.GetPointAttr(name).Data<float>();
}
inline double Sigmoid(double x) { return 1 / (1 + std::exp(-x)); }

// ---- the shared files ----

}  // namespace spz_test
}  // namespace io
}  // namespace t
}  // namespace open3d
