// Small SPZ files that claim huge scenes are refused by the memory check before anything is
// decompressed: a 61 KB v4 file of RLE zstd frames claiming 1e8 splats once decoded 2 GB for
// 11 s first, and a 2 MB gzip bomb named .spz inflated 2 GiB before its 16-byte header was
// read. The streams here are not even valid compressed data: had the reader decompressed
// before the check, the error would be about the data, not the memory.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/io/ByteCodecs.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace tests {
namespace {

using Bytes = std::vector<uint8_t>;

constexpr uint32_t kMagic = 0x5053474e;  // "NGSP"
constexpr uint32_t kClaimed = 100000000;

std::string ErrorOfReading(const std::string& path) {
    t::geometry::PointCloud cloud;
    try {
        t::io::ReadPointCloud(path, cloud);
    } catch (const core::Open3DError& e) {
        return e.what();
    }
    return "";
}

TEST(SpzBomb, V4StreamsAreNotDecompressedBeforeTheMemoryCheck) {
    // SH degree 0, version 4: positions 9, alphas 1, colours 3, scales 3, rotations 4 bytes a
    // splat. Each stream's compressed size is the least the zstd bound (32768x) allows.
    const uint64_t per_splat[] = {9, 1, 3, 3, 4};
    Bytes b;
    AppendU32(b, kMagic);
    AppendU32(b, 4);
    AppendU32(b, kClaimed);
    b.insert(b.end(), {0, 12, 0, 5});
    AppendU32(b, 32);  // the TOC right after the 32-byte header
    b.resize(32, 0);
    uint64_t payload = 0;
    for (uint64_t bytes : per_splat) {
        const uint64_t uncompressed = bytes * kClaimed;
        const uint64_t compressed = (uncompressed + 32767) / 32768;
        AppendU64(b, compressed);
        AppendU64(b, uncompressed);
        payload += compressed;
    }
    b.resize(b.size() + payload, 0x5a);  // no zstd frame at all
    const std::string path = TempDir() + "/claims_1e8.spz";
    WriteFileBytes(path, b);
    ScopedEnvironment limit("OPEN3D_HOST_MEMORY_LIMIT", "1G");
    const std::string message = ErrorOfReading(path);
    // 1e8 splats of 14 floats (5.6 GB) beside their 2.0 GB of decoded streams; 1 GiB holds
    // 1073741824 / 76 of them.
    EXPECT_NE(message.find("100000000 splats of SH degree 0 and 2000000000 bytes of "
                           "decompressed streams needs 7.60 GB of memory, 1.07 GB is "
                           "available (OPEN3D_HOST_MEMORY_LIMIT); at most 14128181 splats fit"),
              std::string::npos)
        << message;
}

TEST(SpzBomb, GzipStreamInflatesItsHeaderFirst) {
    Bytes header;
    AppendU32(header, kMagic);
    AppendU32(header, 2);
    AppendU32(header, kClaimed);
    header.insert(header.end(), {0, 12, 0, 0});
    // A gzip member of the header and 1 MB of zeros: the attributes it claims are nowhere.
    Bytes raw = header;
    raw.resize(raw.size() + (1 << 20), 0);
    const Bytes gz = t::io::GzipBytes(raw.data(), raw.size());
    const std::string path = TempDir() + "/gzip_claims_1e8.spz";
    WriteFileBytes(path, gz);
    ScopedEnvironment limit("OPEN3D_HOST_MEMORY_LIMIT", "1G");
    const std::string message = ErrorOfReading(path);
    // v2: 9 + 1 + 3 + 3 + 3 = 19 bytes of streams a splat beside 56 of columns.
    EXPECT_NE(message.find("100000000 splats of SH degree 0 and 1900000000 bytes of "
                           "decompressed streams needs 7.50 GB of memory"),
              std::string::npos)
        << message;
}

}  // namespace
}  // namespace tests
}  // namespace open3d
