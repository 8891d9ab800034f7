#include "open3d/t/io/ZipArchive.h"

#include <algorithm>
#include <cstring>
#include <limits>

#include "open3d/core/Exception.h"
#include "open3d/t/io/ByteCodecs.h"

namespace open3d {
namespace t {
namespace io {
namespace {

constexpr uint32_t kLocalHeaderSig = 0x04034b50;
constexpr uint32_t kCentralHeaderSig = 0x02014b50;
constexpr uint32_t kEndOfDirSig = 0x06054b50;
constexpr size_t kEndOfDirSize = 22;
constexpr size_t kLocalHeaderSize = 30;
constexpr size_t kCentralHeaderSize = 46;

uint16_t Get16(const uint8_t* p) { return uint16_t(p[0] | (p[1] << 8)); }
uint32_t Get32(const uint8_t* p) {
    return uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24);
}
void Put16(std::vector<uint8_t>& out, uint16_t v) {
    out.push_back(uint8_t(v));
    out.push_back(uint8_t(v >> 8));
}
void Put32(std::vector<uint8_t>& out, uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(uint8_t(v >> (8 * i)));
}

}  // namespace

bool LooksLikeZip(const uint8_t* data, size_t size) {
    return size >= 4 && Get32(data) == kLocalHeaderSig;
}

ZipReader::ZipReader(const uint8_t* data, size_t size, std::string what)
    : data_(data), size_(size), what_(std::move(what)) {
    // The end-of-central-directory record: the last one, searching back over a comment of
    // at most 65535 bytes.
    if (size_ < kEndOfDirSize) core::ThrowError("{}: too small for a zip archive", what_);
    size_t eocd = size_;
    const size_t lowest = size_ > kEndOfDirSize + 65535 ? size_ - kEndOfDirSize - 65535 : 0;
    for (size_t p = size_ - kEndOfDirSize + 1; p-- > lowest;) {
        if (Get32(data_ + p) == kEndOfDirSig) {
            eocd = p;
            break;
        }
    }
    if (eocd == size_) core::ThrowError("{}: no zip end-of-directory record", what_);
    const uint8_t* e = data_ + eocd;
    const uint16_t count = Get16(e + 10);
    const uint64_t dir_size = Get32(e + 12), dir_offset = Get32(e + 16);
    if (Get16(e + 4) != 0 || Get16(e + 6) != 0) {
        core::ThrowError("{}: multi-disk zip archives are not supported", what_);
    }
    if (dir_offset == 0xFFFFFFFFu || count == 0xFFFF) {
        core::ThrowError("{}: zip64 archives are not supported", what_);
    }
    if (dir_offset + dir_size > eocd) {
        core::ThrowError("{}: zip central directory [{}, +{}) lies outside the file", what_,
                         dir_offset, dir_size);
    }
    size_t p = dir_offset;
    for (uint16_t i = 0; i < count; ++i) {
        if (p + kCentralHeaderSize > eocd || Get32(data_ + p) != kCentralHeaderSig) {
            core::ThrowError("{}: zip directory entry {} is malformed", what_, i);
        }
        const uint8_t* h = data_ + p;
        Entry entry;
        entry.method = Get16(h + 10);
        entry.crc = Get32(h + 16);
        entry.compressed_size = Get32(h + 20);
        entry.size = Get32(h + 24);
        const size_t name_len = Get16(h + 28), extra_len = Get16(h + 30),
                     comment_len = Get16(h + 32);
        entry.local_header_offset = Get32(h + 42);
        if (p + kCentralHeaderSize + name_len + extra_len + comment_len > eocd) {
            core::ThrowError("{}: zip directory entry {} runs past the directory", what_, i);
        }
        if (Get16(h + 8) & 1u)
            core::ThrowError("{}: encrypted zip entries are not supported", what_);
        entry.name.assign(reinterpret_cast<const char*>(h + kCentralHeaderSize), name_len);
        entries_.push_back(std::move(entry));
        p += kCentralHeaderSize + name_len + extra_len + comment_len;
    }
}

std::vector<std::string> ZipReader::Names() const {
    std::vector<std::string> names;
    for (const Entry& e : entries_) names.push_back(e.name);
    return names;
}

bool ZipReader::Has(const std::string& name) const {
    return std::any_of(entries_.begin(), entries_.end(),
                       [&](const Entry& e) { return e.name == name; });
}

std::vector<uint8_t> ZipReader::Read(const std::string& name, size_t max_size) const {
    const auto it = std::find_if(entries_.begin(), entries_.end(),
                                 [&](const Entry& e) { return e.name == name; });
    const std::string where = what_ + ": zip entry '" + name + "'";
    if (it == entries_.end()) core::ThrowError("{} is missing", where);
    if (it->size > max_size) {
        core::ThrowError("{} declares {} bytes, more than the {} allowed", where, it->size,
                         max_size);
    }
    const uint64_t h = it->local_header_offset;
    if (h + kLocalHeaderSize > size_ || Get32(data_ + h) != kLocalHeaderSig) {
        core::ThrowError("{}: local header at {} is malformed", where, h);
    }
    const uint64_t start = h + kLocalHeaderSize + Get16(data_ + h + 26) + Get16(data_ + h + 28);
    if (start + it->compressed_size > size_) {
        core::ThrowError("{}: its {} bytes run past the end of the file", where,
                         it->compressed_size);
    }
    const uint8_t* stored = data_ + start;
    std::vector<uint8_t> bytes;
    if (it->method == 0) {
        if (it->compressed_size != it->size) {
            core::ThrowError("{}: stored entry with two sizes ({} and {})", where,
                             it->compressed_size, it->size);
        }
        bytes.assign(stored, stored + it->size);
    } else if (it->method == 8) {
        bytes = InflateRawBytes(stored, it->compressed_size, it->size, where);
    } else {
        core::ThrowError("{}: compression method {} is not supported (only 0 and 8)", where,
                         it->method);
    }
    if (Crc32(bytes.data(), bytes.size()) != it->crc) core::ThrowError("{}: CRC mismatch", where);
    return bytes;
}

void ZipWriter::Add(const std::string& name, const std::vector<uint8_t>& bytes) {
    if (bytes.size() > std::numeric_limits<uint32_t>::max() || name.size() > 0xFFFF) {
        core::ThrowError("zip entry '{}' is too large for a zip archive without zip64", name);
    }
    Entry e;
    e.name = name;
    e.crc = Crc32(bytes.data(), bytes.size());
    e.size = static_cast<uint32_t>(bytes.size());
    std::vector<uint8_t> deflated = DeflateRawBytes(bytes.data(), bytes.size());
    if (deflated.size() < bytes.size()) {
        e.method = 8;
        e.data = std::move(deflated);
    } else {
        e.method = 0;
        e.data = bytes;
    }
    entries_.push_back(std::move(e));
}

std::vector<uint8_t> ZipWriter::Finish() const {
    std::vector<uint8_t> out;
    std::vector<uint32_t> offsets;
    auto common = [&](const Entry& e) {  // version needed .. name length
        Put16(out, 20);                  // version needed: 2.0 (deflate)
        Put16(out, 0);                   // flags
        Put16(out, e.method);
        Put16(out, 0);     // time
        Put16(out, 0x21);  // date: 1980-01-01
        Put32(out, e.crc);
        Put32(out, static_cast<uint32_t>(e.data.size()));
        Put32(out, e.size);
        Put16(out, static_cast<uint16_t>(e.name.size()));
    };
    for (const Entry& e : entries_) {
        offsets.push_back(static_cast<uint32_t>(out.size()));
        Put32(out, kLocalHeaderSig);
        common(e);
        Put16(out, 0);  // extra length
        out.insert(out.end(), e.name.begin(), e.name.end());
        out.insert(out.end(), e.data.begin(), e.data.end());
    }
    const uint32_t dir_offset = static_cast<uint32_t>(out.size());
    for (size_t i = 0; i < entries_.size(); ++i) {
        const Entry& e = entries_[i];
        Put32(out, kCentralHeaderSig);
        Put16(out, 20);  // version made by
        common(e);
        Put16(out, 0);  // extra length
        Put16(out, 0);  // comment length
        Put16(out, 0);  // disk
        Put16(out, 0);  // internal attributes
        Put32(out, 0);  // external attributes
        Put32(out, offsets[i]);
        out.insert(out.end(), e.name.begin(), e.name.end());
    }
    const uint32_t dir_size = static_cast<uint32_t>(out.size()) - dir_offset;
    Put32(out, kEndOfDirSig);
    Put16(out, 0);
    Put16(out, 0);
    Put16(out, static_cast<uint16_t>(entries_.size()));
    Put16(out, static_cast<uint16_t>(entries_.size()));
    Put32(out, dir_size);
    Put32(out, dir_offset);
    Put16(out, 0);  // comment length
    return out;
}

}  // namespace io
}  // namespace t
}  // namespace open3d
