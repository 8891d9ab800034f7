#include "open3d/t/io/ImageIO.h"

#include <png.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/RegularFile.h"

namespace open3d {
namespace t {
namespace io {

namespace {

// libpng reports errors through longjmp; the handler keeps the message for the exception.
struct PngErrorState {
    char message[256] = {0};
};

void PngError(png_structp png, png_const_charp message) {
    auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
    std::snprintf(state->message, sizeof(state->message), "%s", message);
    png_longjmp(png, 1);
}
void PngWarning(png_structp, png_const_charp) {}

int ColorType(int64_t channels) {
    switch (channels) {
        case 1:
            return PNG_COLOR_TYPE_GRAY;
        case 2:
            return PNG_COLOR_TYPE_GRAY_ALPHA;
        case 3:
            return PNG_COLOR_TYPE_RGB;
        default:
            return PNG_COLOR_TYPE_RGBA;
    }
}

// Writes rows of `bit_depth` samples (16-bit rows in host order, little endian assumed).
void WritePngRows(const std::string& filename, int width, int height, int channels, int bit_depth,
                  std::vector<png_bytep>& rows) {
    FILE* file = std::fopen(filename.c_str(), "wb");
    if (!file) core::ThrowError("cannot open '{}' for writing", filename);
    PngErrorState state;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &state, PngError, PngWarning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!png || !info) {
        png_destroy_write_struct(&png, &info);
        std::fclose(file);
        core::ThrowError("libpng could not be initialised for '{}'", filename);
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        std::fclose(file);
        core::ThrowError("failed to write PNG '{}': {}", filename, state.message);
    }
    png_init_io(png, file);
    png_set_IHDR(png, info, width, height, bit_depth, ColorType(channels), PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    if (bit_depth == 16) png_set_swap(png);  // PNG stores big endian
    png_write_image(png, rows.data());
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    if (std::fclose(file) != 0) core::ThrowError("failed to write PNG '{}'", filename);
}

std::string LowerExtension(const std::string& filename) {
    const auto dot = filename.find_last_of('.');
    std::string ext = dot == std::string::npos ? "" : filename.substr(dot + 1);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

// NumPy's dtype string of an image element (little-endian).
const char* NpyDescr(core::Dtype dtype) {
    switch (dtype) {
        case core::Dtype::Float32:
            return "<f4";
        case core::Dtype::UInt8:
            return "|u1";
        case core::Dtype::UInt16:
            return "<u2";
        case core::Dtype::Int32:
            return "<i4";
    }
    core::ThrowError("npy: unknown dtype {}", static_cast<int>(dtype));
}

}  // namespace

void WritePNG(const std::string& filename, const geometry::Image& image) {
    if (image.GetDtype() != core::Dtype::UInt8) {
        core::ThrowError("WritePNG '{}': image must be UInt8 (convert with ToUInt8)", filename);
    }
    if (image.IsEmpty()) core::ThrowError("WritePNG '{}': image is empty", filename);
    const int64_t stride = image.GetCols() * image.GetChannels();
    std::vector<png_bytep> rows(image.GetRows());
    auto* base = const_cast<uint8_t*>(image.Data<uint8_t>());
    for (int64_t y = 0; y < image.GetRows(); ++y) rows[y] = base + y * stride;
    WritePngRows(filename, static_cast<int>(image.GetCols()), static_cast<int>(image.GetRows()),
                 static_cast<int>(image.GetChannels()), 8, rows);
}

int64_t WritePNG16(const std::string& filename, const geometry::Image& image, double scale) {
    if (image.GetDtype() != core::Dtype::Float32 || image.GetChannels() != 1) {
        core::ThrowError("WritePNG16 '{}': image must be Float32 with 1 channel", filename);
    }
    if (image.IsEmpty()) core::ThrowError("WritePNG16 '{}': image is empty", filename);
    std::vector<uint16_t> values(image.NumPixels());
    const float* src = image.Data<float>();
    int64_t saturated = 0;
    for (size_t i = 0; i < values.size(); ++i) {
        const double scaled = static_cast<double>(src[i]) * scale;
        saturated += scaled > 65535.5;  // would round above the largest value
        const double v = std::clamp(scaled, 0.0, 65535.0);
        values[i] = v >= 0.0 ? static_cast<uint16_t>(std::lround(v)) : 0;  // NaN -> 0
    }
    std::vector<png_bytep> rows(image.GetRows());
    for (int64_t y = 0; y < image.GetRows(); ++y) {
        rows[y] = reinterpret_cast<png_bytep>(values.data() + y * image.GetCols());
    }
    WritePngRows(filename, static_cast<int>(image.GetCols()), static_cast<int>(image.GetRows()), 1,
                 16, rows);
    return saturated;
}

namespace {

// The libpng calls that may longjmp run in these two frames, which hold only plain C data:
// a longjmp must not skip a C++ destructor (GCC's -Wclobbered and LeakSanitizer agree).
struct PngLayout {
    int width = 0, height = 0, channels = 0, depth = 0;
    size_t row_bytes = 0;
};

bool ReadPngLayout(png_structp png, png_infop info, FILE* file, PngLayout* layout) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_init_io(png, file);
    png_set_sig_bytes(png, 8);
    png_read_info(png, info);
    const int color_type = png_get_color_type(png, info);
    const int bit_depth = png_get_bit_depth(png, info);
    if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
    if (color_type == PNG_COLOR_TYPE_GRAY && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
    if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
    if (bit_depth == 16) png_set_swap(png);
    png_read_update_info(png, info);
    layout->width = static_cast<int>(png_get_image_width(png, info));
    layout->height = static_cast<int>(png_get_image_height(png, info));
    layout->channels = png_get_channels(png, info);
    layout->depth = png_get_bit_depth(png, info);
    layout->row_bytes = png_get_rowbytes(png, info);
    return true;
}

bool ReadPngRows(png_structp png, png_bytep* rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_read_image(png, rows);
    png_read_end(png, nullptr);
    return true;
}

}  // namespace

geometry::Image ReadPNG(const std::string& filename) {
    core::RequireRegularFile(filename);
    FILE* file = std::fopen(filename.c_str(), "rb");
    if (!file) core::ThrowError("cannot open PNG '{}'", filename);
    unsigned char signature[8] = {0};
    if (std::fread(signature, 1, 8, file) != 8 || png_sig_cmp(signature, 0, 8) != 0) {
        std::fclose(file);
        core::ThrowError("'{}' is not a PNG file", filename);
    }
    PngErrorState state;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &state, PngError, PngWarning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    auto fail = [&](const char* what) {
        png_destroy_read_struct(&png, &info, nullptr);
        std::fclose(file);
        core::ThrowError("failed to read PNG '{}': {}", filename, what);
    };
    if (!png || !info) fail("libpng could not be initialised");
    PngLayout layout;
    if (!ReadPngLayout(png, info, file, &layout)) fail(state.message);
    std::vector<uint8_t> buffer(layout.row_bytes * layout.height);
    std::vector<png_bytep> rows(layout.height);
    for (int y = 0; y < layout.height; ++y) rows[y] = buffer.data() + y * layout.row_bytes;
    if (!ReadPngRows(png, rows.data())) fail(state.message);
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(file);

    const int width = layout.width, height = layout.height, channels = layout.channels;
    const int out_depth = layout.depth;
    geometry::Image image;
    if (out_depth == 16) {
        image = geometry::Image(height, width, channels, core::Dtype::Float32);
        float* dst = image.Data<float>();
        for (int64_t i = 0; i < static_cast<int64_t>(width) * height * channels; ++i) {
            uint16_t v;
            std::memcpy(&v, buffer.data() + 2 * i, 2);
            dst[i] = static_cast<float>(v);
        }
    } else {
        image = geometry::Image(height, width, channels, core::Dtype::UInt8);
        std::memcpy(image.Data<uint8_t>(), buffer.data(), buffer.size());
    }
    return image;
}

void WriteNpy(const std::string& filename, const geometry::Image& image) {
    std::string header = fmt::format(
        "{{'descr': '{}', 'fortran_order': False, 'shape': ({}, {}, {}), }}",
        NpyDescr(image.GetDtype()), image.GetRows(), image.GetCols(), image.GetChannels());
    // Magic (6) + version (2) + length (2) + header + '\n' is padded to a multiple of 64.
    const size_t total = 10 + header.size() + 1;
    header.append((64 - total % 64) % 64, ' ');
    header.push_back('\n');
    std::ofstream out(filename, std::ios::binary);
    if (!out) core::ThrowError("cannot open '{}' for writing", filename);
    const char magic[8] = {'\x93', 'N', 'U', 'M', 'P', 'Y', 1, 0};
    out.write(magic, 8);
    const uint16_t len = static_cast<uint16_t>(header.size());
    const char len_bytes[2] = {static_cast<char>(len & 0xff), static_cast<char>(len >> 8)};
    out.write(len_bytes, 2);
    out.write(header.data(), static_cast<std::streamsize>(header.size()));
    out.write(static_cast<const char*>(image.AsTensor().RawData()), image.AsTensor().NumBytes());
    if (!out) core::ThrowError("failed to write '{}'", filename);
}

geometry::Image ReadNpy(const std::string& filename) {
    core::RequireRegularFile(filename);
    std::ifstream in(filename, std::ios::binary);
    if (!in) core::ThrowError("cannot open '{}'", filename);
    char magic[10] = {0};
    in.read(magic, 10);
    if (!in || std::memcmp(magic, "\x93NUMPY", 6) != 0 || magic[6] != 1) {
        core::ThrowError("'{}' is not a version 1 .npy file", filename);
    }
    const size_t len = static_cast<uint8_t>(magic[8]) | (static_cast<uint8_t>(magic[9]) << 8);
    std::string header(len, '\0');
    in.read(header.data(), static_cast<std::streamsize>(len));
    std::optional<core::Dtype> dtype;
    for (const core::Dtype d :
         {core::Dtype::Float32, core::Dtype::UInt8, core::Dtype::UInt16, core::Dtype::Int32}) {
        if (header.find(fmt::format("'{}'", NpyDescr(d))) != std::string::npos) dtype = d;
    }
    long long rows = 0, cols = 0, channels = 0;
    const auto shape_pos = header.find("'shape': (");
    if (!in || !dtype || header.find("'fortran_order': False") == std::string::npos ||
        shape_pos == std::string::npos ||
        std::sscanf(header.c_str() + shape_pos, "'shape': (%lld, %lld, %lld)", &rows, &cols,
                    &channels) != 3) {
        core::ThrowError(
            "'{}': unsupported .npy header (need '<f4', '|u1' or '<u2', C order, rank 3)",
            filename);
    }
    geometry::Image image(rows, cols, channels, *dtype);
    core::Tensor tensor = image.AsTensor();
    in.read(static_cast<char*>(tensor.RawData()), tensor.NumBytes());
    if (!in) core::ThrowError("'{}': .npy data is truncated", filename);
    return geometry::Image(tensor);
}

void WriteImage(const std::string& filename, const geometry::Image& image) {
    const std::string ext = LowerExtension(filename);
    if (ext == "png") {
        WritePNG(filename, image.ToUInt8());
    } else if (ext == "npy") {
        WriteNpy(filename, image);
    } else {
        core::ThrowError("cannot write image '{}': unknown extension (use .png or .npy)", filename);
    }
}

}  // namespace io
}  // namespace t
}  // namespace open3d
