// The compressed PLY reader (layout and choices: CompressedPlyLayout.h).
#include "open3d/t/io/CompressedPlyLayout.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using namespace compressed_ply;

// ---------------------------------------------------------------------------------------
// Reader.

const char* PlyTypeName(PlyType type) {  // in PlyType's order
    static const char* const kNames[] = {"char", "uchar", "short", "ushort",
                                         "int",  "uint",  "float", "double"};
    return kNames[static_cast<int>(type)];
}

// Byte offset of a required scalar property of the given type inside the element's row.
int64_t RequireProperty(const std::string& filename, const PlyElement& element,
                        const std::string& name, PlyType type) {
    const int index = element.FindProperty(name);
    if (index < 0) {
        core::ThrowError("'{}': missing required property '{}' in element '{}' (compressed PLY)",
                         filename, name, element.name);
    }
    const PlyProperty& p = element.properties[index];
    if (p.type != type) {
        core::ThrowError(
            "'{}': property '{}' of element '{}' is {}; compressed PLY stores it as {}", filename,
            name, element.name, PlyTypeName(p.type), PlyTypeName(type));
    }
    return p.offset;
}

template <typename T>
T LoadLE(const uint8_t* p) {  // the file is little endian, as is every host we build for
    T value;
    std::memcpy(&value, p, sizeof(T));
    return value;
}

}  // namespace

geometry::PointCloud ReadCompressedPly(const std::string& filename,
                                       const ReadPointCloudOptions& options,
                                       ReadPointCloudReport& report) {
    const MappedFile bytes(filename);
    const PlyHeader header = ParsePlyHeader(filename, bytes.data(), bytes.size());
    if (header.encoding != PlyEncoding::BinaryLittleEndian) {
        core::ThrowError("'{}': compressed PLY must be binary_little_endian, this file is {}",
                         filename,
                         header.encoding == PlyEncoding::Ascii ? "ascii" : "binary_big_endian");
    }

    // Each element's rows follow the previous element's; all must be fixed-size and fit.
    const uint64_t size = bytes.size();
    uint64_t offset = header.data_offset;
    const PlyElement *chunk = nullptr, *vertex = nullptr, *sh = nullptr;
    uint64_t chunk_offset = 0, vertex_offset = 0, sh_offset = 0;
    for (const PlyElement& e : header.elements) {
        if (e.HasList()) {
            core::ThrowError(
                "'{}': element '{}' has a list property; compressed PLY elements have "
                "fixed-size rows",
                filename, e.name);
        }
        const uint64_t row = static_cast<uint64_t>(e.RowSize());
        const uint64_t remaining = size - offset;
        if (row > 0 && static_cast<uint64_t>(e.count) > remaining / row) {
            core::ThrowError(
                "'{}': element '{}' declares {} rows of {} bytes but only {} bytes remain: the "
                "file is truncated or the count is wrong",
                filename, e.name, e.count, row, remaining);
        }
        auto locate = [&](const char* name, const PlyElement*& found, uint64_t& found_offset) {
            if (e.name != name) return;
            if (found != nullptr) {
                core::ThrowError("'{}': element '{}' appears twice", filename, e.name);
            }
            found = &e;
            found_offset = offset;
        };
        locate("chunk", chunk, chunk_offset);
        locate("vertex", vertex, vertex_offset);
        locate("sh", sh, sh_offset);
        offset += static_cast<uint64_t>(e.count) * row;
    }
    if (chunk == nullptr) {
        core::ThrowError("'{}': compressed PLY has no 'chunk' element", filename);
    }
    if (vertex == nullptr) {
        core::ThrowError("'{}': compressed PLY has no 'vertex' element", filename);
    }

    // Chunk bounds: 12 required, the 6 colour bounds all or none.
    int64_t chunk_props[kChunkFloats];
    for (int k = 0; k < 12; ++k) {
        chunk_props[k] = RequireProperty(filename, *chunk, kChunkNames[k], PlyType::Float32);
    }
    int num_colour = 0;
    for (int k = 12; k < kChunkFloats; ++k) num_colour += chunk->FindProperty(kChunkNames[k]) >= 0;
    const bool colour_bounds = num_colour > 0;
    if (colour_bounds) {
        for (int k = 12; k < kChunkFloats; ++k) {
            if (chunk->FindProperty(kChunkNames[k]) < 0) {
                core::ThrowError(
                    "'{}': element 'chunk' has {} of the 6 colour bounds but not '{}' (all of "
                    "min_r .. max_b or none)",
                    filename, num_colour, kChunkNames[k]);
            }
            chunk_props[k] = RequireProperty(filename, *chunk, kChunkNames[k], PlyType::Float32);
        }
    }
    int64_t vertex_props[4];
    for (int k = 0; k < 4; ++k) {
        vertex_props[k] = RequireProperty(filename, *vertex, kVertexNames[k], PlyType::UInt32);
    }

    const int64_t n = vertex->count;
    const int64_t num_chunks = (n + kChunkSplats - 1) / kChunkSplats;
    if (chunk->count != num_chunks) {
        core::ThrowError(
            "'{}': element 'chunk' has {} rows; {} vertices need ceil({} / 256) = {} chunks",
            filename, chunk->count, n, n, num_chunks);
    }

    int degree = 0;
    std::vector<int64_t> sh_props;
    if (sh != nullptr) {
        int num_rest = 0;
        while (sh->FindProperty("f_rest_" + std::to_string(num_rest)) >= 0) ++num_rest;
        for (const PlyProperty& p : sh->properties) {
            if (p.name.rfind("f_rest_", 0) != 0) continue;
            int k = -1;
            const char* end = p.name.data() + p.name.size();
            const auto [ptr, ec] = std::from_chars(p.name.data() + 7, end, k);
            if (ec == std::errc() && ptr == end && k >= num_rest) {
                core::ThrowError(
                    "'{}': element 'sh': f_rest properties are not contiguous ('{}' present, "
                    "'f_rest_{}' missing)",
                    filename, p.name, num_rest);
            }
        }
        degree = -1;
        for (int d = 1; d <= 3; ++d) {
            if (num_rest == 3 * NumSHRestCoeffs(d)) degree = d;
        }
        if (degree < 0) {
            core::ThrowError(
                "'{}': element 'sh' has {} f_rest properties; expected 9, 24 or 45 (SH degree "
                "1, 2 or 3)",
                filename, num_rest);
        }
        for (int k = 0; k < num_rest; ++k) {
            sh_props.push_back(
                RequireProperty(filename, *sh, "f_rest_" + std::to_string(k), PlyType::UInt8));
        }
        if (sh->count != n) {
            core::ThrowError("'{}': element 'sh' has {} rows but element 'vertex' has {}", filename,
                             sh->count, n);
        }
    }

    // The chunk table, 18 floats per chunk (the colour bounds unused without them).
    std::vector<float> bounds(num_chunks * kChunkFloats, 0.0f);
    const int64_t chunk_row = chunk->RowSize();
    for (int64_t c = 0; c < num_chunks; ++c) {
        const uint8_t* row = bytes.data() + chunk_offset + c * chunk_row;
        for (int k = 0; k < (colour_bounds ? kChunkFloats : 12); ++k) {
            bounds[c * kChunkFloats + k] = LoadLE<float>(row + chunk_props[k]);
        }
    }

    SplatColumns columns;
    columns.Allocate(filename, n, /*gaussian=*/true, degree);
    float* positions = columns.positions.Data<float>();
    float* scale = columns.scale.Data<float>();
    float* rot = columns.rot.Data<float>();
    float* opacity = columns.opacity.Data<float>();
    float* f_dc = columns.f_dc.Data<float>();
    const int nc = NumSHRestCoeffs(degree);
    float* f_rest = nc > 0 ? columns.f_rest.Data<float>() : nullptr;
    const int64_t vertex_row = vertex->RowSize();
    const int64_t sh_row = sh != nullptr ? sh->RowSize() : 0;
    core::ParallelFor(
        n,
        [&](int64_t i) {
            const float* b = bounds.data() + (i / kChunkSplats) * kChunkFloats;
            const uint8_t* row = bytes.data() + vertex_offset + i * vertex_row;
            const uint32_t packed_position = LoadLE<uint32_t>(row + vertex_props[0]);
            const uint32_t packed_rotation = LoadLE<uint32_t>(row + vertex_props[1]);
            const uint32_t packed_scale = LoadLE<uint32_t>(row + vertex_props[2]);
            const uint32_t packed_color = LoadLE<uint32_t>(row + vertex_props[3]);
            for (int f = 0; f < 3; ++f) {
                const int shift = kShift111011[f], bits = kBits111011[f];
                positions[i * 3 + f] = DecodeLinear(b[f], b[3 + f], packed_position >> shift, bits);
                scale[i * 3 + f] = DecodeScale(b[6 + f], b[9 + f], packed_scale >> shift, bits);
                f_dc[i * 3 + f] =
                    DecodeColour(colour_bounds, b[12 + f], b[15 + f], packed_color >> (24 - 8 * f));
            }
            opacity[i] = DecodeOpacity(packed_color);
            DecodeRotation(packed_rotation, rot + i * 4);
            if (f_rest != nullptr) {
                const uint8_t* sh_bytes = bytes.data() + sh_offset + i * sh_row;
                for (int c = 0; c < 3; ++c) {
                    for (int k = 0; k < nc; ++k) {
                        f_rest[(i * nc + k) * 3 + c] = DecodeSH(sh_bytes[sh_props[c * nc + k]]);
                    }
                }
            }
        },
        2048);

    report.trailing_bytes = static_cast<int64_t>(size - offset);
    if (report.trailing_bytes > 0) {
        core::LogWarning("'{}': ignoring {} bytes after the declared elements", filename,
                         report.trailing_bytes);
    }
    return FinalizeColumns(filename, columns, options, report);
}

}  // namespace io
}  // namespace t
}  // namespace open3d
