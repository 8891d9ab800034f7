// Internal to t/io: zip archives (PKWARE APPNOTE 6.3), as far as bundled SOG files use them:
// entries stored (method 0) or deflated (method 8), no encryption, no zip64, no spanning.
// The reader works on bytes already in memory (a mapped file) and checks every offset and
// size against them; the writer deflates each entry.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace open3d {
namespace t {
namespace io {

/// True when `data` starts like a zip archive (a local file header, "PK\3\4").
bool LooksLikeZip(const uint8_t* data, size_t size);

class ZipReader {
public:
    /// Parses the central directory of the archive in [data, data + size), which must stay
    /// valid while the reader is used. `what` names it in errors.
    ZipReader(const uint8_t* data, size_t size, std::string what);

    /// Entry names in directory order.
    std::vector<std::string> Names() const;
    bool Has(const std::string& name) const;
    /// The entry's bytes (inflated and CRC-checked); throws naming the entry when it is
    /// missing, corrupt or larger than max_size.
    std::vector<uint8_t> Read(const std::string& name, size_t max_size = size_t(1) << 31) const;

private:
    struct Entry {
        std::string name;
        uint16_t method = 0;
        uint32_t crc = 0;
        uint64_t compressed_size = 0, size = 0, local_header_offset = 0;
    };
    const uint8_t* data_;
    size_t size_;
    std::string what_;
    std::vector<Entry> entries_;
};

class ZipWriter {
public:
    /// Adds an entry (deflated unless that makes it larger, then stored).
    void Add(const std::string& name, const std::vector<uint8_t>& bytes);
    /// The whole archive: local headers and data, central directory, end record.
    std::vector<uint8_t> Finish() const;

private:
    struct Entry {
        std::string name;
        uint16_t method;
        uint32_t crc;
        uint32_t size;
        std::vector<uint8_t> data;  // as stored
    };
    std::vector<Entry> entries_;
};

}  // namespace io
}  // namespace t
}  // namespace open3d
