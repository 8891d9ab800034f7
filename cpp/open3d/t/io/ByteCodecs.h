// Internal to t/io: the byte-stream codecs of the compressed splat formats (gzip for SPZ
// v1-3, zstd for SPZ v4 streams, raw deflate inside zip archives). Every decoder takes an
// upper bound on its output, so a small malicious file cannot make it allocate gigabytes;
// errors throw core::Open3DError with `what` (the file and the stream) in the message.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace open3d {
namespace t {
namespace io {

/// A gzip member (RFC 1952) inflated; throws when it is malformed or inflates past max_output.
std::vector<uint8_t> GunzipBytes(const uint8_t* data, size_t size, size_t max_output,
                                 const std::string& what);
/// The first bytes of a gzip member, at most `max_output` of them: inflation stops there
/// without error (a header can be read before the rest is allowed to take memory).
/// `*more` tells whether the member holds more than was returned. Throws when what was
/// inflated is malformed.
std::vector<uint8_t> GunzipPrefixBytes(const uint8_t* data, size_t size, size_t max_output,
                                       bool* more, const std::string& what);
/// `data` as one gzip member (deflate level 6).
std::vector<uint8_t> GzipBytes(const uint8_t* data, size_t size);

/// Raw deflate data (RFC 1951, as in zip entries) inflated to exactly `expected_size` bytes.
std::vector<uint8_t> InflateRawBytes(const uint8_t* data, size_t size, size_t expected_size,
                                     const std::string& what);
/// `data` as raw deflate data (level 6).
std::vector<uint8_t> DeflateRawBytes(const uint8_t* data, size_t size);

/// One zstd frame decompressed to exactly `expected_size` bytes.
std::vector<uint8_t> ZstdDecompressBytes(const uint8_t* data, size_t size, size_t expected_size,
                                         const std::string& what);
/// `data` as one zstd frame (level 12: SPZ files are written once and read often).
std::vector<uint8_t> ZstdCompressBytes(const uint8_t* data, size_t size);

/// CRC-32 (zip, gzip) of `data`.
uint32_t Crc32(const uint8_t* data, size_t size);

}  // namespace io
}  // namespace t
}  // namespace open3d
