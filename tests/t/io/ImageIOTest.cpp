#include <gtest/gtest.h>

#include <fstream>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/io/ImageIO.h"

namespace open3d {
namespace tests {

using t::geometry::Image;

Image Pattern(int64_t channels, core::Dtype dtype) {
    Image img(5, 7, channels, dtype);
    for (int64_t i = 0; i < img.AsTensor().NumElements(); ++i) {
        if (dtype == core::Dtype::UInt8) {
            img.Data<uint8_t>()[i] = static_cast<uint8_t>((i * 37) % 256);
        } else {
            img.Data<float>()[i] = static_cast<float>(i) * 0.37f - 3.0f;
        }
    }
    return img;
}

TEST(ImageIO, PngRoundTrip8Bit) {
    const std::string dir = TempDir();
    for (int64_t channels : {1, 2, 3, 4}) {
        const Image img = Pattern(channels, core::Dtype::UInt8);
        const std::string path = dir + "/img" + std::to_string(channels) + ".png";
        t::io::WritePNG(path, img);
        EXPECT_EQ(t::io::ReadPNG(path), img) << channels << " channels";
    }
}

TEST(ImageIO, Png16BitDepth) {
    const std::string path = TempDir() + "/depth.png";
    Image depth(2, 3, 1, core::Dtype::Float32);
    depth.At<float>(0, 0) = 1.2345f;  // 1234.5 mm rounds to 1235 (half away from zero)
    depth.At<float>(0, 1) = 70.0f;    // clamps to 65535
    depth.At<float>(1, 2) = 0.0004f;  // rounds to 0
    depth.At<float>(1, 1) = 0.2561f;
    EXPECT_EQ(t::io::WritePNG16(path, depth, 1000.0), 1);  // the 70 m pixel saturated
    const Image back = t::io::ReadPNG(path);
    ASSERT_EQ(back.GetDtype(), core::Dtype::Float32);
    EXPECT_EQ(back.At<float>(0, 0), 1235.0f);
    EXPECT_EQ(back.At<float>(0, 1), 65535.0f);
    EXPECT_EQ(back.At<float>(1, 2), 0.0f);
    EXPECT_EQ(back.At<float>(1, 1), 256.0f);
}

TEST(ImageIO, NpyRoundTripIsExact) {
    const std::string dir = TempDir();
    const Image f = Pattern(4, core::Dtype::Float32);
    t::io::WriteNpy(dir + "/f.npy", f);
    EXPECT_EQ(t::io::ReadNpy(dir + "/f.npy"), f);
    const Image u = Pattern(3, core::Dtype::UInt8);
    t::io::WriteImage(dir + "/u.npy", u);
    EXPECT_EQ(t::io::ReadNpy(dir + "/u.npy"), u);
    Image w(5, 7, 1, core::Dtype::UInt16);  // normalised depth ('<u2')
    for (int64_t i = 0; i < w.NumPixels(); ++i) w.Data<uint16_t>()[i] = uint16_t(i * 1871);
    t::io::WriteNpy(dir + "/w.npy", w);
    EXPECT_EQ(t::io::ReadNpy(dir + "/w.npy"), w);
    // The header is a multiple of 64 bytes, as numpy requires.
    std::ifstream in(dir + "/f.npy", std::ios::binary | std::ios::ate);
    EXPECT_EQ((static_cast<int64_t>(in.tellg()) - f.AsTensor().NumBytes()) % 64, 0);
}

TEST(ImageIO, ErrorsNameTheFile) {
    const std::string dir = TempDir();
    try {
        t::io::ReadPNG(dir + "/missing.png");
        FAIL();
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos);
    }
    std::ofstream(dir + "/bad.png") << "not a png at all";
    EXPECT_THROW(t::io::ReadPNG(dir + "/bad.png"), core::Open3DError);
    // A truncated PNG fails inside libpng: the error must surface as an exception.
    t::io::WritePNG(dir + "/ok.png", Pattern(3, core::Dtype::UInt8));
    {
        std::ifstream in(dir + "/ok.png", std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(in)), {});
        std::ofstream(dir + "/cut.png", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    }
    EXPECT_THROW(t::io::ReadPNG(dir + "/cut.png"), core::Open3DError);
    EXPECT_THROW(t::io::WritePNG(dir + "/f.png", Pattern(3, core::Dtype::Float32)),
                 core::Open3DError);
    EXPECT_THROW(t::io::WriteImage(dir + "/x.bmp", Pattern(3, core::Dtype::UInt8)),
                 core::Open3DError);
}

}  // namespace tests
}  // namespace open3d
