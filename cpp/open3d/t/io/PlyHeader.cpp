#include "open3d/t/io/PlyHeader.h"

#include <charconv>
#include <sstream>

#include "open3d/core/Exception.h"

namespace open3d {
namespace t {
namespace io {

int PlyTypeSize(PlyType type) {
    switch (type) {
        case PlyType::Int8:
        case PlyType::UInt8:
            return 1;
        case PlyType::Int16:
        case PlyType::UInt16:
            return 2;
        case PlyType::Int32:
        case PlyType::UInt32:
        case PlyType::Float32:
            return 4;
        case PlyType::Float64:
            return 8;
    }
    return 0;
}

bool PlyElement::HasList() const {
    for (const auto& p : properties) {
        if (p.is_list) return true;
    }
    return false;
}

int64_t PlyElement::RowSize() const {
    int64_t size = 0;
    for (const auto& p : properties) size += PlyTypeSize(p.type);
    return size;
}

int PlyElement::FindProperty(const std::string& property_name) const {
    for (size_t i = 0; i < properties.size(); ++i) {
        if (properties[i].name == property_name) return static_cast<int>(i);
    }
    return -1;
}

namespace {

bool ParseType(const std::string& word, PlyType& type) {
    static const std::pair<const char*, PlyType> kNames[] = {
        {"char", PlyType::Int8},      {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},
        {"uint8", PlyType::UInt8},    {"short", PlyType::Int16},     {"int16", PlyType::Int16},
        {"ushort", PlyType::UInt16},  {"uint16", PlyType::UInt16},   {"int", PlyType::Int32},
        {"int32", PlyType::Int32},    {"uint", PlyType::UInt32},     {"uint32", PlyType::UInt32},
        {"float", PlyType::Float32},  {"float32", PlyType::Float32}, {"double", PlyType::Float64},
        {"float64", PlyType::Float64}};
    for (const auto& [name, t] : kNames) {
        if (word == name) {
            type = t;
            return true;
        }
    }
    return false;
}

// A header line as an error message shows it: binary bytes (a file whose header never
// ends runs into its data) as \xNN, and at most 80 characters.
std::string Printable(const std::string& line) {
    std::string out;
    for (const unsigned char c : line.substr(0, 80)) {
        if (c >= 0x20 && c < 0x7f) {
            out += static_cast<char>(c);
        } else {
            out += fmt::format("\\x{:02x}", c);
        }
    }
    return line.size() > 80 ? out + "..." : out;
}

}  // namespace

PlyHeader ParsePlyHeader(const std::string& filename, const uint8_t* bytes, size_t size) {
    // Headers are short; refuse to scan more than 1 MiB for end_header.
    const size_t limit = std::min<size_t>(size, 1 << 20);
    const std::string_view text(reinterpret_cast<const char*>(bytes), limit);
    if (text.substr(0, 3) != "ply")
        core::ThrowError("'{}' is not a PLY file (no 'ply' magic)", filename);
    // Looked for first: without it the line parser below would stop at the first line of
    // binary data and print it, hiding that the header never ends.
    const size_t end_line = text.find("\nend_header");
    if (end_line == std::string_view::npos ||
        text.find('\n', end_line + 1) == std::string_view::npos) {
        core::ThrowError(
            "'{}': the PLY header is incomplete: no 'end_header' line {} {} bytes (the file is "
            "truncated or its header is damaged)",
            filename, limit < size ? "within the first" : "in all of its", limit);
    }

    PlyHeader header;
    bool have_format = false;
    size_t pos = 0;
    int line_number = 0;
    for (;;) {
        const size_t eol = text.find('\n', pos);
        if (eol == std::string_view::npos) {
            core::ThrowError("'{}': PLY header has no 'end_header' line (truncated header)",
                             filename);
        }
        std::string line(text.substr(pos, eol - pos));
        pos = eol + 1;
        ++line_number;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream in(line);
        std::string keyword;
        in >> keyword;
        auto fail = [&](const std::string& why) {
            core::ThrowError("'{}': PLY header line {} ('{}'): {}", filename, line_number,
                             Printable(line), why);
        };
        if (keyword.empty() || keyword == "comment" || keyword == "obj_info") continue;
        if (line_number == 1) {
            if (line != "ply") fail("first line must be 'ply'");
            continue;
        }
        if (keyword == "format") {
            std::string encoding, version;
            in >> encoding >> version;
            if (encoding == "ascii") {
                header.encoding = PlyEncoding::Ascii;
            } else if (encoding == "binary_little_endian") {
                header.encoding = PlyEncoding::BinaryLittleEndian;
            } else if (encoding == "binary_big_endian") {
                header.encoding = PlyEncoding::BinaryBigEndian;
            } else {
                fail("unknown format '" + encoding + "'");
            }
            have_format = true;
        } else if (keyword == "element") {
            PlyElement element;
            std::string count;
            in >> element.name >> count;
            int64_t value = -1;
            const auto [ptr, ec] =
                std::from_chars(count.data(), count.data() + count.size(), value);
            if (element.name.empty() || ec != std::errc() || ptr != count.data() + count.size() ||
                value < 0) {
                fail("element needs a name and a non-negative count");
            }
            element.count = value;
            // A second 'vertex' made the reader take the last one (0 splats, rc 0).
            for (const PlyElement& earlier : header.elements) {
                if (earlier.name == element.name)
                    fail("element '" + element.name + "' declared twice");
            }
            header.elements.push_back(element);
        } else if (keyword == "property") {
            if (header.elements.empty()) fail("property before any element");
            PlyProperty property;
            std::string type_word;
            in >> type_word;
            if (type_word == "list") {
                std::string count_type, item_type;
                in >> count_type >> item_type >> property.name;
                property.is_list = true;
                if (!ParseType(count_type, property.list_count_type) ||
                    !ParseType(item_type, property.type)) {
                    fail("unsupported list property types");
                }
            } else {
                in >> property.name;
                if (!ParseType(type_word, property.type)) {
                    fail("unsupported property type '" + type_word + "'");
                }
            }
            if (property.name.empty()) fail("property without a name");
            PlyElement& element = header.elements.back();
            if (element.FindProperty(property.name) >= 0) fail("duplicate property");
            property.offset = element.RowSize();
            element.properties.push_back(property);
        } else if (keyword == "end_header") {
            break;
        } else {
            fail("unknown keyword '" + keyword + "'");
        }
    }
    if (!have_format) core::ThrowError("'{}': PLY header has no 'format' line", filename);
    header.data_offset = pos;
    return header;
}

}  // namespace io
}  // namespace t
}  // namespace open3d
