// Test helpers that write small PLY and .splat files byte by byte, independently of the
// writer under test, so the reader is checked against files we fully control.
#pragma once

#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace tests {

/// The 3DGS property names for an SH degree, in the trainer's order.
inline std::vector<std::string> GaussianPropertyNames(int degree) {
    std::vector<std::string> names = {"x",  "y",      "z",      "nx",    "ny",
                                      "nz", "f_dc_0", "f_dc_1", "f_dc_2"};
    const int rest = 3 * t::geometry::NumSHRestCoeffs(degree);
    for (int k = 0; k < rest; ++k) names.push_back("f_rest_" + std::to_string(k));
    for (const char* n :
         {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"}) {
        names.push_back(n);
    }
    return names;
}

/// Writes a binary little-endian PLY with float properties; `rows` holds names.size()
/// floats per vertex; `declared` overrides the vertex count in the header when >= 0.
inline void WriteFloatPly(const std::string& path, const std::vector<std::string>& names,
                          const std::vector<float>& rows, int64_t declared = -1,
                          const std::string& extra_bytes = "") {
    const int64_t n = static_cast<int64_t>(rows.size() / names.size());
    std::ofstream out(path, std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\nelement vertex " << (declared >= 0 ? declared : n)
        << "\n";
    for (const auto& name : names) out << "property float " << name << "\n";
    out << "end_header\n";
    out.write(reinterpret_cast<const char*>(rows.data()), rows.size() * sizeof(float));
    out << extra_bytes;
}

/// One plausible splat row for GaussianPropertyNames(degree): position (i, 2i, 3i),
/// log-scales -2, -3, -4, rot (1, 0, 0, 0), opacity 0.5, f_dc and f_rest small values.
inline std::vector<float> PlausibleRow(int degree, int i) {
    std::vector<float> row;
    for (const auto& name : GaussianPropertyNames(degree)) {
        float v = 0.0f;
        if (name == "x") v = float(i);
        if (name == "y") v = float(2 * i);
        if (name == "z") v = float(3 * i);
        if (name.rfind("f_dc", 0) == 0) v = 0.25f;
        if (name.rfind("f_rest", 0) == 0) v = 0.01f * float(name.size());
        if (name == "opacity") v = 0.5f;
        if (name == "scale_0") v = -2.0f;
        if (name == "scale_1") v = -3.0f;
        if (name == "scale_2") v = -4.0f;
        if (name == "rot_0") v = 1.0f;
        row.push_back(v);
    }
    return row;
}

inline std::vector<float> PlausibleRows(int degree, int n) {
    std::vector<float> rows;
    for (int i = 0; i < n; ++i) {
        const auto row = PlausibleRow(degree, i);
        rows.insert(rows.end(), row.begin(), row.end());
    }
    return rows;
}

inline void WriteText(const std::string& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

}  // namespace tests
}  // namespace open3d
