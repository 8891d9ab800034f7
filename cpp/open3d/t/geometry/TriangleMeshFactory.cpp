// Primitive meshes: a UV sphere and an axis-aligned box, counter-clockwise from outside.
#include <cmath>
#include <numbers>

#include "open3d/core/Exception.h"
#include "open3d/t/geometry/TriangleMesh.h"

namespace open3d {
namespace t {
namespace geometry {

using core::Dtype;
using core::Tensor;

namespace {

void StoreRow(float* rows, int64_t i, const Eigen::Vector3d& v) {
    for (int k = 0; k < 3; ++k) rows[3 * i + k] = static_cast<float>(v[k]);
}

}  // namespace

TriangleMesh TriangleMesh::CreateSphere(double radius, int resolution) {
    if (!(std::isfinite(radius) && radius > 0.0)) {
        core::ThrowError("CreateSphere needs a finite radius > 0, got {}", radius);
    }
    // Below 2 there is no ring; above 32768 the vertex count 2r(r-1)+2 exceeds int32 indices.
    if (resolution < 2 || resolution > 32768) {
        core::ThrowError("CreateSphere needs 2 <= resolution <= 32768, got {}", resolution);
    }
    const int num_rings = resolution - 1;  // latitude circles between the poles
    const int ring_size = 2 * resolution;  // vertices per ring
    const int64_t num_vertices = int64_t(ring_size) * num_rings + 2;
    const double step = std::numbers::pi / resolution;  // both polar and azimuthal spacing

    Tensor positions({num_vertices, 3}, Dtype::Float32);
    Tensor normals({num_vertices, 3}, Dtype::Float32);
    float* p = positions.Data<float>();  // [N, 3]
    float* n = normals.Data<float>();    // [N, 3]
    // Vertex 0 is the north pole (+z), vertex 1 the south pole, then ring by ring from the
    // north; the unit direction is also the exact normal.
    auto set_vertex = [&](int64_t i, const Eigen::Vector3d& direction) {
        StoreRow(p, i, radius * direction);
        StoreRow(n, i, direction);
    };
    set_vertex(0, Eigen::Vector3d(0, 0, 1));
    set_vertex(1, Eigen::Vector3d(0, 0, -1));
    auto ring_vertex = [&](int ring, int j) { return 2 + ring * ring_size + j % ring_size; };
    for (int ring = 0; ring < num_rings; ++ring) {
        const double polar = step * (ring + 1);
        for (int j = 0; j < ring_size; ++j) {
            const double azimuth = step * j;
            set_vertex(ring_vertex(ring, j),
                       Eigen::Vector3d(std::sin(polar) * std::cos(azimuth),
                                       std::sin(polar) * std::sin(azimuth), std::cos(polar)));
        }
    }

    // Azimuth grows counter-clockwise seen from +z, so seen from outside (looking at the centre)
    // the order "upper-left, lower-left, lower-right" is counter-clockwise.
    TriangleIndices triangles;
    triangles.reserve(size_t(4) * resolution * (resolution - 1));
    const int last = num_rings - 1;
    for (int j = 0; j < ring_size; ++j) {
        triangles.emplace_back(0, ring_vertex(0, j), ring_vertex(0, j + 1));
        triangles.emplace_back(1, ring_vertex(last, j + 1), ring_vertex(last, j));
    }
    for (int ring = 0; ring < last; ++ring) {
        for (int j = 0; j < ring_size; ++j) {
            const int upper0 = ring_vertex(ring, j), upper1 = ring_vertex(ring, j + 1);
            const int lower0 = ring_vertex(ring + 1, j), lower1 = ring_vertex(ring + 1, j + 1);
            triangles.emplace_back(upper0, lower0, lower1);
            triangles.emplace_back(upper0, lower1, upper1);
        }
    }

    TriangleMesh mesh(std::move(positions), std::move(triangles));
    mesh.SetVertexNormals(std::move(normals));
    return mesh;
}

TriangleMesh TriangleMesh::CreateBox(double width, double height, double depth) {
    const Eigen::Vector3d extent(width, height, depth);
    if (!(extent.allFinite() && (extent.array() > 0.0).all())) {
        core::ThrowError("CreateBox needs finite sizes > 0, got ({}, {}, {})", width, height,
                         depth);
    }
    constexpr int kNumVertices = 24;
    Tensor positions({kNumVertices, 3}, Dtype::Float32);
    Tensor normals({kNumVertices, 3}, Dtype::Float32);
    float* p = positions.Data<float>();  // [24, 3]
    float* n = normals.Data<float>();    // [24, 3]
    TriangleIndices triangles;
    // Face (axis k, side s) with in-plane axes u = k+1, v = k+2 (cyclic, so e_u x e_v = e_k):
    // corners (0,0), (1,0), (1,1), (0,1) in (u, v) wind counter-clockwise around +e_k, and
    // the reverse order around -e_k.
    const double kCorners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    int vertex = 0;
    for (int k = 0; k < 3; ++k) {
        const int u = (k + 1) % 3, v = (k + 2) % 3;
        for (int side = 0; side < 2; ++side) {
            const int base = vertex;
            for (int c = 0; c < 4; ++c) {
                const int corner = side == 1 ? c : 3 - c;
                Eigen::Vector3d unit = Eigen::Vector3d::Zero();
                unit[k] = side;
                unit[u] = kCorners[corner][0];
                unit[v] = kCorners[corner][1];
                Eigen::Vector3d normal = Eigen::Vector3d::Zero();
                normal[k] = side == 1 ? 1.0 : -1.0;
                StoreRow(p, vertex, unit.cwiseProduct(extent));
                StoreRow(n, vertex, normal);
                ++vertex;
            }
            triangles.emplace_back(base, base + 1, base + 2);
            triangles.emplace_back(base, base + 2, base + 3);
        }
    }
    TriangleMesh mesh(std::move(positions), std::move(triangles));
    mesh.SetVertexNormals(std::move(normals));
    return mesh;
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
