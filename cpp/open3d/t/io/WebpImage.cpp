#include "open3d/t/io/WebpImage.h"

#include <webp/decode.h>
#include <webp/encode.h>

#include "open3d/core/Exception.h"

namespace open3d {
namespace t {
namespace io {

Rgba8Image DecodeWebp(const uint8_t* data, size_t size, const std::string& what,
                      int64_t max_pixels) {
    Rgba8Image image;
    if (!WebPGetInfo(data, size, &image.width, &image.height)) {
        core::ThrowError("{}: not a valid WebP image", what);
    }
    if (int64_t(image.width) * image.height > max_pixels) {
        core::ThrowError("{}: {}x{} pixels is more than the {} allowed", what, image.width,
                         image.height, max_pixels);
    }
    image.rgba.resize(size_t(image.width) * image.height * 4);
    if (!WebPDecodeRGBAInto(data, size, image.rgba.data(), image.rgba.size(), image.width * 4)) {
        core::ThrowError("{}: corrupt WebP image data", what);
    }
    return image;
}

std::vector<uint8_t> EncodeWebpLossless(const Rgba8Image& image) {
    WebPConfig config;
    WebPPicture picture;
    if (!WebPConfigInit(&config) || !WebPPictureInit(&picture)) {
        core::ThrowError("libwebp version mismatch");
    }
    config.lossless = 1;
    config.exact = 1;  // keep the RGB of transparent pixels: they are data here
    config.quality = 75;
    config.method = 4;
    picture.use_argb = 1;
    picture.width = image.width;
    picture.height = image.height;
    if (!WebPPictureImportRGBA(&picture, image.rgba.data(), image.width * 4)) {
        WebPPictureFree(&picture);
        core::ThrowError("WebP: out of memory importing a {}x{} image", image.width, image.height);
    }
    WebPMemoryWriter writer;
    WebPMemoryWriterInit(&writer);
    picture.writer = WebPMemoryWrite;
    picture.custom_ptr = &writer;
    const int ok = WebPEncode(&config, &picture);
    WebPPictureFree(&picture);
    std::vector<uint8_t> out(writer.mem, writer.mem + writer.size);
    WebPMemoryWriterClear(&writer);
    if (!ok) core::ThrowError("WebP encoding failed (error {})", int(picture.error_code));
    return out;
}

}  // namespace io
}  // namespace t
}  // namespace open3d
