// The byte-level pieces of the compressed formats: gzip, raw deflate and zstd round trips
// with their size limits, zip archives (ours read back, and corrupt ones refused), and
// lossless WebP keeping every byte, transparent pixels included.
#include <gtest/gtest.h>

#include <numeric>
#include <random>

#include "open3d/core/Exception.h"
#include "open3d/t/io/ByteCodecs.h"
#include "open3d/t/io/WebpImage.h"
#include "open3d/t/io/ZipArchive.h"

namespace open3d {
namespace tests {
namespace {

using namespace t::io;

std::vector<uint8_t> SomeBytes(size_t n) {
    std::mt19937 rng(5);
    std::vector<uint8_t> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = uint8_t(i % 7 == 0 ? rng() : i / 13);
    return v;
}

template <typename F>
void ExpectThrowContaining(F&& f, const std::string& fragment) {
    try {
        f();
        ADD_FAILURE() << "no exception, expected one containing '" << fragment << "'";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

TEST(ByteCodecs, RoundTripsAndLimits) {
    const std::vector<uint8_t> data = SomeBytes(200000);
    const auto gz = GzipBytes(data.data(), data.size());
    EXPECT_EQ(gz[0], 0x1f);  // the gzip magic
    EXPECT_EQ(gz[1], 0x8b);
    EXPECT_EQ(GunzipBytes(gz.data(), gz.size(), data.size(), "t"), data);
    ExpectThrowContaining([&] { GunzipBytes(gz.data(), gz.size(), data.size() - 1, "t"); },
                          "more than");
    ExpectThrowContaining([&] { GunzipBytes(gz.data(), gz.size() / 2, data.size(), "t"); },
                          "truncated");
    const auto raw = DeflateRawBytes(data.data(), data.size());
    EXPECT_EQ(InflateRawBytes(raw.data(), raw.size(), data.size(), "t"), data);
    const auto zs = ZstdCompressBytes(data.data(), data.size());
    EXPECT_EQ(ZstdDecompressBytes(zs.data(), zs.size(), data.size(), "t"), data);
    ExpectThrowContaining([&] { ZstdDecompressBytes(zs.data(), zs.size(), 10, "t"); }, "zstd");
    // The CRC-32 of "123456789" is the standard check value 0xCBF43926.
    const char* check = "123456789";
    EXPECT_EQ(Crc32(reinterpret_cast<const uint8_t*>(check), 9), 0xCBF43926u);
}

TEST(ZipArchive, WrittenArchivesReadBackAndCorruptionIsRefused) {
    ZipWriter writer;
    const std::vector<uint8_t> a = SomeBytes(5000), b = {1, 2, 3};
    writer.Add("meta.json", a);
    writer.Add("x.webp", b);  // incompressible: stored
    std::vector<uint8_t> zip = writer.Finish();
    ASSERT_TRUE(LooksLikeZip(zip.data(), zip.size()));
    ZipReader reader(zip.data(), zip.size(), "t.sog");
    EXPECT_EQ(reader.Names(), (std::vector<std::string>{"meta.json", "x.webp"}));
    EXPECT_EQ(reader.Read("meta.json"), a);
    EXPECT_EQ(reader.Read("x.webp"), b);
    ExpectThrowContaining([&] { reader.Read("none"); }, "'none' is missing");
    ExpectThrowContaining([&] { reader.Read("meta.json", 100); }, "more than the 100 allowed");
    zip[40] ^= 0xFF;  // inside the first entry's data
    ZipReader corrupt(zip.data(), zip.size(), "t.sog");
    EXPECT_THROW(corrupt.Read("meta.json"), core::Open3DError);
    ExpectThrowContaining([&] { ZipReader(zip.data(), 10, "t.sog"); }, "too small");
}

TEST(WebpImage, LosslessKeepsEveryByte) {
    Rgba8Image image;
    image.width = 37;
    image.height = 11;
    image.rgba = SomeBytes(size_t(37) * 11 * 4);
    for (size_t i = 3; i < image.rgba.size(); i += 8) image.rgba[i] = 0;  // transparent pixels
    const auto webp = EncodeWebpLossless(image);
    const Rgba8Image back = DecodeWebp(webp.data(), webp.size(), "t");
    EXPECT_EQ(back.width, 37);
    EXPECT_EQ(back.height, 11);
    EXPECT_EQ(back.rgba, image.rgba);
    ExpectThrowContaining([&] { DecodeWebp(webp.data(), 8, "t.webp"); }, "t.webp");
}

}  // namespace
}  // namespace tests
}  // namespace open3d
