// 3DGS PLY reader: binary little/big endian and ASCII, property order free, extra
// properties and elements ignored, SH degree 0..3 from the number of f_rest properties.

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/core/Progress.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/PlyHeader.h"
#include "open3d/t/io/SplatColumns.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using geometry::NumSHRestCoeffs;

// One value copied from a PLY row into an output column.
struct Field {
    int property = 0;  // index into the vertex element's properties
    float* dest = nullptr;
    int dest_stride = 0;  // floats per point in the destination column
    int dest_index = 0;   // position inside the point's row of the destination column
    bool exp = false;     // log-scale: store exp(value)
};

template <typename T>
T Load(const uint8_t* p, bool swap) {
    uint8_t buffer[sizeof(T)];
    std::memcpy(buffer, p, sizeof(T));
    if (swap) std::reverse(buffer, buffer + sizeof(T));
    T value;
    std::memcpy(&value, buffer, sizeof(T));
    return value;
}

double LoadValue(const uint8_t* p, PlyType type, bool swap) {
    switch (type) {
        case PlyType::Int8:
            return Load<int8_t>(p, swap);
        case PlyType::UInt8:
            return Load<uint8_t>(p, swap);
        case PlyType::Int16:
            return Load<int16_t>(p, swap);
        case PlyType::UInt16:
            return Load<uint16_t>(p, swap);
        case PlyType::Int32:
            return Load<int32_t>(p, swap);
        case PlyType::UInt32:
            return Load<uint32_t>(p, swap);
        case PlyType::Float32:
            return Load<float>(p, swap);
        case PlyType::Float64:
            return Load<double>(p, swap);
    }
    return 0.0;
}

void Store(const Field& f, int64_t i, double value) {
    f.dest[i * f.dest_stride + f.dest_index] =
        f.exp ? DecodeLogScale(static_cast<float>(value)) : static_cast<float>(value);
}

// Works out which properties go where, allocating the columns for `count` points.
std::vector<Field> PlanFields(const std::string& filename, const PlyElement& vertex,
                              SplatColumns& columns) {
    auto find = [&](const std::string& name) { return vertex.FindProperty(name); };
    auto require = [&](const std::string& name) {
        const int index = find(name);
        if (index < 0) {
            core::ThrowError("'{}': missing required property '{}' in element 'vertex'", filename,
                             name);
        }
        if (vertex.properties[index].is_list) {
            core::ThrowError("'{}': property '{}' is a list; a scalar is required", filename, name);
        }
        return index;
    };

    static const char* kGaussianNames[] = {"f_dc_0",  "f_dc_1",  "f_dc_2",  "opacity",
                                           "scale_0", "scale_1", "scale_2", "rot_0",
                                           "rot_1",   "rot_2",   "rot_3"};
    bool gaussian = find("f_rest_0") >= 0;
    for (const char* name : kGaussianNames) gaussian = gaussian || find(name) >= 0;

    int num_rest = 0;
    while (find("f_rest_" + std::to_string(num_rest)) >= 0) ++num_rest;
    for (const auto& p : vertex.properties) {
        if (p.name.rfind("f_rest_", 0) == 0) {
            int k = -1;
            const char* begin = p.name.data() + 7;
            const auto [ptr, ec] = std::from_chars(begin, p.name.data() + p.name.size(), k);
            if (ec == std::errc() && ptr == p.name.data() + p.name.size() && k >= num_rest) {
                core::ThrowError(
                    "'{}': f_rest properties are not contiguous ('{}' present, "
                    "'f_rest_{}' missing)",
                    filename, p.name, num_rest);
            }
        }
    }
    int degree = -1;
    for (int d = 0; d <= 3; ++d) {
        if (num_rest == 3 * NumSHRestCoeffs(d)) degree = d;
    }
    if (degree < 0) {
        core::ThrowError("'{}': {} f_rest properties; expected 0, 9, 24 or 45 (SH degree 0..3)",
                         filename, num_rest);
    }

    columns.Allocate(filename, vertex.count, gaussian, degree);
    std::vector<Field> fields;
    auto add = [&](const std::string& name, core::Tensor& column, int stride, int index,
                   bool exp = false) {
        fields.push_back(Field{require(name), column.Data<float>(), stride, index, exp});
    };
    add("x", columns.positions, 3, 0);
    add("y", columns.positions, 3, 1);
    add("z", columns.positions, 3, 2);
    if (!gaussian) return fields;
    for (int c = 0; c < 3; ++c) add("f_dc_" + std::to_string(c), columns.f_dc, 3, c);
    add("opacity", columns.opacity, 1, 0);
    for (int c = 0; c < 3; ++c) add("scale_" + std::to_string(c), columns.scale, 3, c, true);
    for (int c = 0; c < 4; ++c) add("rot_" + std::to_string(c), columns.rot, 4, c);
    // The file stores f_rest channel-major: f_rest_[c * Nc + k]; we store [Nc, 3].
    const int nc = NumSHRestCoeffs(degree);
    for (int c = 0; c < 3; ++c) {
        for (int k = 0; k < nc; ++k) {
            add("f_rest_" + std::to_string(c * nc + k), columns.f_rest, nc * 3, k * 3 + c);
        }
    }
    return fields;
}

void ReadBinaryVertices(const PlyElement& vertex, const std::vector<Field>& fields,
                        const uint8_t* data, bool swap) {
    const int64_t stride = vertex.RowSize();
    bool all_float = !swap;
    for (const Field& f : fields) {
        all_float = all_float && vertex.properties[f.property].type == PlyType::Float32;
    }
    // In 32 reported blocks when someone watches (the same values either way).
    const int64_t blocks =
        core::HasProgressCallback() && vertex.count > (int64_t(1) << 18) ? 32 : 1;
    for (int64_t b = 0; b < blocks; ++b) {
        if (blocks > 1) core::ReportProgress("decoding", double(b) / blocks);
        const int64_t first = vertex.count * b / blocks;
        core::ParallelForRange(
            vertex.count * (b + 1) / blocks - first,
            [&](int64_t begin, int64_t end) {
                for (int64_t i = first + begin; i < first + end; ++i) {
                    const uint8_t* row = data + i * stride;
                    for (const Field& f : fields) {
                        const PlyProperty& p = vertex.properties[f.property];
                        if (all_float) {
                            float value;
                            std::memcpy(&value, row + p.offset, 4);
                            Store(f, i, value);
                        } else {
                            Store(f, i, LoadValue(row + p.offset, p.type, swap));
                        }
                    }
                }
            },
            2048);
    }
    if (blocks > 1) core::ReportProgress("decoding", 1.0);
}

// Cursor over whitespace-separated ASCII tokens.
struct AsciiCursor {
    const char* pos;
    const char* end;

    bool Next(std::string_view& token) {
        while (pos < end && std::isspace(static_cast<unsigned char>(*pos))) ++pos;
        if (pos == end) return false;
        const char* start = pos;
        while (pos < end && !std::isspace(static_cast<unsigned char>(*pos))) ++pos;
        token = std::string_view(start, pos - start);
        return true;
    }
    void SkipLine() {
        while (pos < end && *pos != '\n') ++pos;
        if (pos < end) ++pos;
    }
};

void ReadAsciiVertices(const std::string& filename, const PlyElement& vertex,
                       const std::vector<Field>& fields, AsciiCursor& cursor) {
    std::vector<std::vector<int>> targets(vertex.properties.size());
    for (size_t f = 0; f < fields.size(); ++f) targets[fields[f].property].push_back(int(f));
    std::string_view token;
    for (int64_t i = 0; i < vertex.count; ++i) {
        for (size_t p = 0; p < vertex.properties.size(); ++p) {
            if (!cursor.Next(token)) {
                core::ThrowError(
                    "'{}': ASCII data ends inside vertex {} of {} (truncated file or "
                    "vertex count too large)",
                    filename, i, vertex.count);
            }
            if (targets[p].empty()) continue;
            double value = 0.0;
            const auto [ptr, ec] =
                std::from_chars(token.data(), token.data() + token.size(), value);
            if (ptr != token.data() + token.size() ||
                (ec != std::errc() && ec != std::errc::result_out_of_range)) {
                core::ThrowError("'{}': vertex {} property '{}': cannot parse '{}' as a number",
                                 filename, i, vertex.properties[p].name, token);
            }
            // from_chars leaves the value unset when it is out of double's range: strtod
            // gives +-HUGE_VAL for an overflow (refused below as non-finite, as 1e300 is in
            // a float property) and the rounded tiny value or 0 for an underflow.
            if (ec == std::errc::result_out_of_range) {
                value = std::strtod(std::string(token).c_str(), nullptr);
            }
            for (int f : targets[p]) Store(fields[f], i, value);
        }
    }
}

}  // namespace

geometry::PointCloud ReadPly(const std::string& filename, const ReadPointCloudOptions& options,
                             ReadPointCloudReport& report) {
    const MappedFile bytes(filename);
    const PlyHeader header = ParsePlyHeader(filename, bytes.data(), bytes.size());
    int vertex_index = -1;
    for (size_t e = 0; e < header.elements.size(); ++e) {
        if (header.elements[e].name == "vertex") vertex_index = static_cast<int>(e);
    }
    if (vertex_index < 0) core::ThrowError("'{}': PLY file has no 'vertex' element", filename);
    const PlyElement& vertex = header.elements[vertex_index];
    const bool ascii = header.encoding == PlyEncoding::Ascii;
    if (vertex.HasList()) {
        core::ThrowError("'{}': list properties in element 'vertex' are not supported", filename);
    }

    size_t offset = header.data_offset;
    const size_t size = bytes.size();
    AsciiCursor cursor{reinterpret_cast<const char*>(bytes.data()) + offset,
                       reinterpret_cast<const char*>(bytes.data()) + size};
    // Skip elements declared before the vertices.
    for (int e = 0; e < vertex_index; ++e) {
        const PlyElement& element = header.elements[e];
        if (ascii) {
            for (int64_t i = 0; i < element.count && cursor.pos < cursor.end; ++i)
                cursor.SkipLine();
            continue;
        }
        if (element.HasList()) {
            core::ThrowError(
                "'{}': element '{}' with list properties before 'vertex' is not "
                "supported",
                filename, element.name);
        }
        const int64_t row = element.RowSize();
        if (row > 0 && element.count > static_cast<int64_t>((size - offset) / row)) {
            core::ThrowError("'{}': element '{}' declares {} rows but the file ends first",
                             filename, element.name, element.count);
        }
        offset += element.count * row;
    }

    // Bound the allocation by what the file can hold before allocating anything.
    const int64_t available = ascii ? cursor.end - cursor.pos : static_cast<int64_t>(size - offset);
    // ASCII rows take at least 2 bytes per property ("0 ... 0\n"; the last newline optional).
    const int64_t min_row =
        ascii ? 2 * static_cast<int64_t>(vertex.properties.size()) : vertex.RowSize();
    const int64_t max_rows = min_row > 0 ? (available + (ascii ? 1 : 0)) / min_row : 0;
    if (vertex.count > max_rows) {
        core::ThrowError(
            "'{}': header declares {} vertices but the data holds at most {} ({} bytes "
            "follow, {} bytes per vertex): the file is truncated or the count is wrong",
            filename, vertex.count, max_rows, available, min_row);
    }

    SplatColumns columns;
    const std::vector<Field> fields = PlanFields(filename, vertex, columns);
    if (ascii) {
        ReadAsciiVertices(filename, vertex, fields, cursor);
    } else {
        ReadBinaryVertices(vertex, fields, bytes.data() + offset,
                           header.encoding == PlyEncoding::BinaryBigEndian);
    }

    // Bytes after everything the header declares are ignored, with a warning.
    bool later_sizes_known = !ascii;
    int64_t declared_after = 0;
    for (size_t e = vertex_index + 1; e < header.elements.size(); ++e) {
        later_sizes_known = later_sizes_known && !header.elements[e].HasList();
        // Counts come from the file (2^62 overflowed here): past the file's size, the
        // declared bytes only say that nothing trails.
        int64_t element_bytes = 0;
        if (__builtin_mul_overflow(header.elements[e].count, int64_t(header.elements[e].RowSize()),
                                   &element_bytes) ||
            __builtin_add_overflow(declared_after, element_bytes, &declared_after)) {
            declared_after = std::numeric_limits<int64_t>::max();
        }
    }
    if (ascii && vertex_index + 1 == static_cast<int>(header.elements.size())) {
        std::string_view token;
        const char* rest = cursor.pos;
        if (cursor.Next(token)) report.trailing_bytes = cursor.end - rest;
    } else if (later_sizes_known) {
        const int64_t vertex_bytes = vertex.count * int64_t(vertex.RowSize());  // <= available
        report.trailing_bytes = declared_after >= available - vertex_bytes
                                    ? 0
                                    : available - vertex_bytes - declared_after;
    }
    if (report.trailing_bytes > 0) {
        core::LogWarning("'{}': ignoring {} bytes after the {} declared vertices", filename,
                         report.trailing_bytes, vertex.count);
    }
    return FinalizeColumns(filename, columns, options, report);
}

}  // namespace io
}  // namespace t
}  // namespace open3d
