// Internal to t/io: the PLY header (format, elements, typed properties) and its parser.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace open3d {
namespace t {
namespace io {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

int PlyTypeSize(PlyType type);

struct PlyProperty {
    std::string name;
    PlyType type = PlyType::Float32;
    bool is_list = false;
    PlyType list_count_type = PlyType::UInt8;
    int64_t offset = 0;  // byte offset inside a binary row (fixed-size elements only)
};

struct PlyElement {
    std::string name;
    int64_t count = 0;
    std::vector<PlyProperty> properties;
    bool HasList() const;
    /// Bytes per row in binary files; only meaningful when !HasList().
    int64_t RowSize() const;
    /// Index of the property with this name, or -1.
    int FindProperty(const std::string& name) const;
};

enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct PlyHeader {
    PlyEncoding encoding = PlyEncoding::BinaryLittleEndian;
    std::vector<PlyElement> elements;
    size_t data_offset = 0;  // first byte after "end_header\n"
};

/// Parses the header at the start of `bytes`. Throws naming `filename` and the header
/// line on anything malformed or unsupported.
PlyHeader ParsePlyHeader(const std::string& filename, const uint8_t* bytes, size_t size);

}  // namespace io
}  // namespace t
}  // namespace open3d
