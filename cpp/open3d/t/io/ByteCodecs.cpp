#include "open3d/t/io/ByteCodecs.h"

#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <limits>

#include <fmt/format.h>

#include "open3d/core/Exception.h"

namespace open3d {
namespace t {
namespace io {
namespace {

// zlib's window bits: 15 + 16 reads/writes a gzip wrapper, -15 raw deflate.
constexpr int kGzipWindow = 15 + 16;
constexpr int kRawWindow = -15;

// Inflates with `window_bits` until the stream ends; the output may not pass max_output.
// With `more` set, reaching max_output stops without error and *more says whether the
// stream goes on.
std::vector<uint8_t> Inflate(const uint8_t* data, size_t size, size_t max_output, int window_bits,
                             const std::string& what, bool* more = nullptr) {
    if (size > std::numeric_limits<uInt>::max()) core::ThrowError("{}: too large", what);
    z_stream zs{};
    if (inflateInit2(&zs, window_bits) != Z_OK) core::ThrowError("{}: zlib init failed", what);
    zs.next_in = const_cast<Bytef*>(data);
    zs.avail_in = static_cast<uInt>(size);
    std::vector<uint8_t> out;
    std::string error;
    for (;;) {
        if (zs.avail_out == 0) {  // grow the output, doubling, up to max_output
            const size_t used = out.size();
            if (used >= max_output) {
                if (more != nullptr) {
                    // One more byte tells whether the stream ends here.
                    uint8_t probe = 0;
                    zs.next_out = &probe;
                    zs.avail_out = 1;
                    const int status = inflate(&zs, Z_NO_FLUSH);
                    *more = zs.avail_out == 0 || (status != Z_STREAM_END && status != Z_OK);
                    zs.total_out = used;
                    break;
                }
                error = fmt::format("decompresses to more than {} bytes", max_output);
                break;
            }
            const size_t grow = std::min({std::max<size_t>(used, 1 << 16), max_output - used,
                                          size_t(std::numeric_limits<uInt>::max())});
            out.resize(used + grow);
            zs.next_out = out.data() + used;
            zs.avail_out = static_cast<uInt>(grow);
        }
        const int status = inflate(&zs, Z_NO_FLUSH);
        if (status == Z_STREAM_END) break;
        if (status == Z_OK || (status == Z_BUF_ERROR && zs.avail_out == 0)) continue;
        error = status == Z_BUF_ERROR
                    ? std::string("truncated compressed data")
                    : fmt::format("corrupt compressed data ({})", zs.msg ? zs.msg : "zlib error");
        break;
    }
    out.resize(zs.total_out);
    inflateEnd(&zs);
    if (!error.empty()) core::ThrowError("{}: {}", what, error);
    return out;
}

std::vector<uint8_t> Deflate(const uint8_t* data, size_t size, int window_bits) {
    z_stream zs{};
    if (deflateInit2(&zs, 6, Z_DEFLATED, window_bits, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
        core::ThrowError("zlib deflate init failed");
    }
    std::vector<uint8_t> out(deflateBound(&zs, static_cast<uLong>(size)) + 32);
    zs.next_in = const_cast<Bytef*>(data);
    zs.avail_in = static_cast<uInt>(size);
    zs.next_out = out.data();
    zs.avail_out = static_cast<uInt>(out.size());
    const int status = deflate(&zs, Z_FINISH);
    out.resize(zs.total_out);
    deflateEnd(&zs);
    if (status != Z_STREAM_END) core::ThrowError("zlib deflate failed ({})", status);
    return out;
}

}  // namespace

std::vector<uint8_t> GunzipBytes(const uint8_t* data, size_t size, size_t max_output,
                                 const std::string& what) {
    return Inflate(data, size, max_output, kGzipWindow, what);
}

std::vector<uint8_t> GunzipPrefixBytes(const uint8_t* data, size_t size, size_t max_output,
                                       bool* more, const std::string& what) {
    *more = false;
    return Inflate(data, size, max_output, kGzipWindow, what, more);
}

std::vector<uint8_t> GzipBytes(const uint8_t* data, size_t size) {
    return Deflate(data, size, kGzipWindow);
}

std::vector<uint8_t> InflateRawBytes(const uint8_t* data, size_t size, size_t expected_size,
                                     const std::string& what) {
    std::vector<uint8_t> out = Inflate(data, size, expected_size, kRawWindow, what);
    if (out.size() != expected_size) {
        core::ThrowError("{}: inflates to {} bytes, {} expected", what, out.size(), expected_size);
    }
    return out;
}

std::vector<uint8_t> DeflateRawBytes(const uint8_t* data, size_t size) {
    return Deflate(data, size, kRawWindow);
}

std::vector<uint8_t> ZstdDecompressBytes(const uint8_t* data, size_t size, size_t expected_size,
                                         const std::string& what) {
    std::vector<uint8_t> out(expected_size);
    const size_t got = ZSTD_decompress(out.data(), out.size(), data, size);
    if (ZSTD_isError(got)) {
        core::ThrowError("{}: corrupt zstd data ({})", what, ZSTD_getErrorName(got));
    }
    if (got != expected_size) {
        core::ThrowError("{}: decompresses to {} bytes, {} expected", what, got, expected_size);
    }
    return out;
}

std::vector<uint8_t> ZstdCompressBytes(const uint8_t* data, size_t size) {
    std::vector<uint8_t> out(ZSTD_compressBound(size));
    const size_t got = ZSTD_compress(out.data(), out.size(), data, size, 12);
    if (ZSTD_isError(got)) core::ThrowError("zstd compression failed: {}", ZSTD_getErrorName(got));
    out.resize(got);
    return out;
}

uint32_t Crc32(const uint8_t* data, size_t size) {
    uLong crc = crc32(0L, Z_NULL, 0);
    while (size > 0) {
        const uInt chunk = static_cast<uInt>(std::min<size_t>(size, 1u << 30));
        crc = crc32(crc, data, chunk);
        data += chunk;
        size -= chunk;
    }
    return static_cast<uint32_t>(crc);
}

}  // namespace io
}  // namespace t
}  // namespace open3d
