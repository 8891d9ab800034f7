// TriangleMesh: primitives checked against analytic numbers (radius, polyhedral area, box
// volume), validation messages, and transforms of positions, normals and winding.
#include "open3d/t/geometry/TriangleMesh.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "open3d/core/Exception.h"

namespace open3d {
namespace t {
namespace geometry {
namespace {

using core::Dtype;
using core::Tensor;
using std::numbers::pi;

Eigen::Vector3d Row(const Tensor& rows, int64_t i) {
    const float* p = rows.Data<float>() + 3 * i;
    return Eigen::Vector3d(p[0], p[1], p[2]);
}

std::array<Eigen::Vector3d, 3> Corners(const TriangleMesh& mesh, int64_t t) {
    const Eigen::Vector3i& tri = mesh.GetTriangleIndices()[t];
    const Tensor& p = mesh.GetVertexPositions();
    return {Row(p, tri[0]), Row(p, tri[1]), Row(p, tri[2])};
}

// (b - a) x (c - a): twice the area times the counter-clockwise normal.
Eigen::Vector3d FaceNormal(const TriangleMesh& mesh, int64_t t) {
    const auto [a, b, c] = Corners(mesh, t);
    return (b - a).cross(c - a);
}

// Smallest dot(face normal, centroid - inside) over all triangles: > 0 means every
// triangle of a convex mesh around `inside` faces outward.
double MinOutwardness(const TriangleMesh& mesh, const Eigen::Vector3d& inside) {
    double min_dot = std::numeric_limits<double>::infinity();
    for (int64_t t = 0; t < mesh.NumTriangles(); ++t) {
        const auto [a, b, c] = Corners(mesh, t);
        const Eigen::Vector3d centroid = (a + b + c) / 3.0;
        min_dot = std::min(min_dot, FaceNormal(mesh, t).dot(centroid - inside));
    }
    return min_dot;
}

// Vertex ids with coincident positions merged, so that meshes with split vertices (the
// box's 24) can be checked for closedness too.
std::vector<int> WeldedIds(const TriangleMesh& mesh) {
    std::map<std::array<float, 3>, int> ids;
    std::vector<int> welded;
    const float* p = mesh.GetVertexPositions().Data<float>();
    for (int64_t i = 0; i < mesh.NumVertices(); ++i) {
        const std::array<float, 3> key{p[3 * i], p[3 * i + 1], p[3 * i + 2]};
        welded.push_back(ids.emplace(key, int(ids.size())).first->second);
    }
    return welded;
}

// A closed, consistently oriented surface uses every directed edge exactly once and its
// reverse exactly once, so every undirected edge belongs to exactly two triangles.
void ExpectClosedAndConsistentlyOriented(const TriangleMesh& mesh) {
    const std::vector<int> id = WeldedIds(mesh);
    std::map<std::pair<int, int>, int> directed;
    for (const Eigen::Vector3i& tri : mesh.GetTriangleIndices()) {
        for (int k = 0; k < 3; ++k) ++directed[{id[tri[k]], id[tri[(k + 1) % 3]]}];
    }
    int bad = 0;
    for (const auto& [edge, count] : directed) {
        const auto reverse = directed.find({edge.second, edge.first});
        const int reverse_count = reverse == directed.end() ? 0 : reverse->second;
        if (count != 1 || reverse_count != 1) ++bad;
    }
    EXPECT_EQ(bad, 0) << "directed edges not used exactly once each way";
    EXPECT_EQ(directed.size(), size_t(3 * mesh.NumTriangles()));
}

// Area of the UV sphere polyhedron from its geometry alone: each band between rings i and
// i + 1 (polar angles i*d and (i+1)*d, d = pi/R) is 2R isosceles trapezoids whose parallel
// sides are chords 2 rho sin(d/2) and whose height joins the chord midpoints; at the poles
// one side is zero and the trapezoid is the cap triangle.
double UVSpherePolyhedronArea(double r, int resolution) {
    const double d = pi / resolution;
    double area = 0.0;
    for (int i = 0; i < resolution; ++i) {
        const double rho0 = i == 0 ? 0.0 : r * std::sin(i * d);
        const double rho1 = i + 1 == resolution ? 0.0 : r * std::sin((i + 1) * d);
        const double chord0 = 2 * rho0 * std::sin(d / 2), chord1 = 2 * rho1 * std::sin(d / 2);
        const double height = std::hypot((rho0 - rho1) * std::cos(d / 2),
                                         r * (std::cos(i * d) - std::cos((i + 1) * d)));
        area += 2 * resolution * 0.5 * (chord0 + chord1) * height;
    }
    return area;
}

TEST(TriangleMeshSphere, CountsFollowTheFormula) {
    for (int res : {2, 3, 5, 20, 33}) {
        const TriangleMesh s = TriangleMesh::CreateSphere(1.0, res);
        EXPECT_EQ(s.NumVertices(), 2 * res * (res - 1) + 2) << res;
        EXPECT_EQ(s.NumTriangles(), 4 * res * (res - 1)) << res;
        // Euler characteristic of a sphere: V - E + F = 2 with E = 3F/2.
        EXPECT_EQ(s.NumVertices() - 3 * s.NumTriangles() / 2 + s.NumTriangles(), 2) << res;
        EXPECT_TRUE(s.HasVertexNormals());
        EXPECT_NO_THROW(s.Validate());
    }
}

TEST(TriangleMeshSphere, EveryVertexLiesAtTheRadius) {
    for (double radius : {1.0, 0.37, 250.0}) {
        const TriangleMesh s = TriangleMesh::CreateSphere(radius, 40);
        double max_error = 0.0;
        for (int64_t i = 0; i < s.NumVertices(); ++i) {
            max_error =
                std::max(max_error, std::abs(Row(s.GetVertexPositions(), i).norm() - radius));
        }
        // Positions are exact in double and rounded once to float: each coordinate moves by
        // at most 2^-24 of its magnitude, so the point by at most 2^-24 * radius. Measured:
        // up to 4.9e-8 * radius at resolution 40.
        EXPECT_LE(max_error, std::ldexp(radius, -24)) << radius;
    }
}

TEST(TriangleMeshSphere, TrianglesFaceOutward) {
    for (int res : {2, 3, 20, 64}) {
        const TriangleMesh s = TriangleMesh::CreateSphere(2.0, res);
        EXPECT_GT(MinOutwardness(s, Eigen::Vector3d::Zero()), 0.0) << res;
    }
}

TEST(TriangleMeshSphere, IsClosedAndConsistentlyOriented) {
    for (int res : {2, 3, 7, 20})
        ExpectClosedAndConsistentlyOriented(TriangleMesh::CreateSphere(1.0, res));
}

TEST(TriangleMeshSphere, AreaMatchesThePolyhedron) {
    // Resolution 2 is the regular octahedron with edge r*sqrt(2): area 4*sqrt(3)*r^2.
    EXPECT_NEAR(TriangleMesh::CreateSphere(1.5, 2).GetSurfaceArea(), 4 * std::sqrt(3.0) * 2.25,
                1e-5);
    for (int res : {10, 20, 40, 80}) {
        const double r = 1.25;
        const double area = TriangleMesh::CreateSphere(r, res).GetSurfaceArea();
        // Float positions (relative error <= 2^-24 each) move the area by ~1e-7 relative.
        const double polyhedron = UVSpherePolyhedronArea(r, res);
        EXPECT_NEAR(area, polyhedron, 1e-6 * polyhedron) << res;
        // An inscribed polyhedron is smaller than the sphere. A face whose corners lie within
        // angular radius rho of its centre loses ~rho^2/2 of its area; here rho^2 =
        // (d^2 + d^2 sin^2(polar)) / 4 with d = pi/R, and sin^2 averages 2/3 over the sphere,
        // so the relative deficit is ~(5 pi^2 / 24) / R^2 (R^2 * deficit measured: 2.043 at
        // R = 10, 2.053 at 20, 2.056 at 80; 5 pi^2 / 24 = 2.056).
        const double sphere = 4 * pi * r * r;
        const double deficit = 1.0 - area / sphere;
        const double predicted = 5 * pi * pi / 24 / (res * res);
        EXPECT_GT(deficit, 0.0) << res;
        EXPECT_NEAR(deficit, predicted, 0.02 * predicted) << res;
    }
}

TEST(TriangleMeshSphere, NormalsAreUnitRadials) {
    const TriangleMesh s = TriangleMesh::CreateSphere(3.0, 16);
    double max_error = 0.0;
    for (int64_t i = 0; i < s.NumVertices(); ++i) {
        const Eigen::Vector3d radial = Row(s.GetVertexPositions(), i).normalized();
        max_error = std::max(max_error, (Row(s.GetVertexNormals(), i) - radial).norm());
    }
    EXPECT_LT(max_error, 2e-7);  // two float roundings of unit-length vectors
}

TEST(TriangleMeshSphere, RejectsBadArguments) {
    EXPECT_THROW(TriangleMesh::CreateSphere(0.0), core::Open3DError);
    EXPECT_THROW(TriangleMesh::CreateSphere(-1.0), core::Open3DError);
    EXPECT_THROW(TriangleMesh::CreateSphere(std::nan("")), core::Open3DError);
    EXPECT_THROW(TriangleMesh::CreateSphere(1.0, 1), core::Open3DError);
}

TEST(TriangleMeshBox, BoundsAreaVolumeAndFlatNormals) {
    const double w = 2.0, h = 0.5, d = 3.0;
    const TriangleMesh box = TriangleMesh::CreateBox(w, h, d);
    EXPECT_NO_THROW(box.Validate());
    EXPECT_EQ(box.NumVertices(), 24);
    EXPECT_EQ(box.NumTriangles(), 12);
    EXPECT_TRUE(box.GetMinBound().isApprox(Eigen::Vector3d::Zero()));
    EXPECT_EQ(box.GetMinBound(), Eigen::Vector3d::Zero());
    EXPECT_EQ(box.GetMaxBound(), Eigen::Vector3d(w, h, d));
    EXPECT_NEAR(box.GetSurfaceArea(), 2 * (w * h + h * d + w * d), 1e-12);
    // Divergence theorem: sum of a . (b x c) / 6 is the enclosed volume, positive only when
    // every triangle winds counter-clockwise from outside.
    double volume = 0.0;
    for (int64_t t = 0; t < box.NumTriangles(); ++t) {
        const auto [a, b, c] = Corners(box, t);
        volume += a.dot(b.cross(c)) / 6.0;
    }
    EXPECT_NEAR(volume, w * h * d, 1e-12);
    EXPECT_GT(MinOutwardness(box, Eigen::Vector3d(w, h, d) / 2), 0.0);
    ExpectClosedAndConsistentlyOriented(box);
    for (int64_t t = 0; t < box.NumTriangles(); ++t) {
        const Eigen::Vector3d face = FaceNormal(box, t).normalized();
        for (int k = 0; k < 3; ++k) {
            const int v = box.GetTriangleIndices()[t][k];
            EXPECT_EQ(Row(box.GetVertexNormals(), v), face) << "triangle " << t;
        }
    }
    EXPECT_THROW(TriangleMesh::CreateBox(1.0, 0.0, 1.0), core::Open3DError);
}

// Runs f and expects an Open3DError whose message contains every fragment.
template <typename F>
void ExpectError(F&& f, const std::vector<std::string>& fragments) {
    try {
        f();
        ADD_FAILURE() << "no exception; expected one mentioning '" << fragments[0] << "'";
    } catch (const core::Open3DError& e) {
        for (const std::string& fragment : fragments) {
            EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
                << "message: " << e.what() << "\nmissing: " << fragment;
        }
    }
}

TriangleMesh TwoTriangles() {
    const Tensor positions =
        Tensor::FromVector<float>({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, {4, 3});
    return TriangleMesh(positions, {{0, 1, 2}, {1, 3, 2}});
}

TEST(TriangleMeshValidate, AcceptsValidAndEmptyMeshes) {
    EXPECT_NO_THROW(TwoTriangles().Validate());
    const TriangleMesh empty;
    EXPECT_TRUE(empty.IsEmpty());
    EXPECT_NO_THROW(empty.Validate());
    EXPECT_EQ(empty.GetMinBound(), Eigen::Vector3d::Zero());
    EXPECT_EQ(empty.GetCenter(), Eigen::Vector3d::Zero());
    EXPECT_THROW(empty.GetVertexPositions(), core::Open3DError);
}

TEST(TriangleMeshValidate, RefusesOutOfRangeIndices) {
    TriangleMesh mesh = TwoTriangles();
    mesh.SetTriangleIndices({{0, 1, 2}, {1, 4, 2}});
    ExpectError([&] { mesh.Validate(); }, {"triangle 1", "vertex index 4", "out of range [0, 4)"});
    ExpectError([&] { mesh.ComputeVertexNormals(); }, {"out of range"});
    mesh.SetTriangleIndices({{-1, 1, 2}});
    ExpectError([&] { mesh.Validate(); }, {"triangle 0", "vertex index -1", "out of range"});
}

TEST(TriangleMeshValidate, RefusesWrongShapesAndDtypes) {
    TriangleMesh mesh = TwoTriangles();
    ExpectError(
        [&] {
            mesh.SetVertexPositions(Tensor({4, 2}, Dtype::Float32));
        },
        {"'positions'", "Float32 [N, 3]", "[4, 2]"});
    ExpectError(
        [&] {
            mesh.SetVertexColors(Tensor({4, 3}, Dtype::UInt8));
        },
        {"'colors'", "Float32 [N, 3]"});
    ExpectError(
        [&] {
            mesh.SetVertexNormals(Tensor({3, 3}, Dtype::Float32));
        },
        {"'normals'", "3 rows, expected 4"});
    // Writable access bypasses the setter; Validate catches it.
    mesh.SetVertexNormals(Tensor({4, 3}, Dtype::Float32));
    mesh.GetVertexAttr("normals") = Tensor({4, 3, 1}, Dtype::Float32);
    ExpectError([&] { mesh.Validate(); }, {"'normals'", "Float32 [N, 3]", "[4, 3, 1]"});
    ExpectError([&] { mesh.Scale(2.0, Eigen::Vector3d::Zero()); }, {"'normals'"});
}

TEST(TriangleMeshValidate, RefusesNonFiniteValuesAndBadColors) {
    TriangleMesh mesh = TwoTriangles();
    Tensor positions = mesh.GetVertexPositions();
    positions.Data<float>()[7] = std::numeric_limits<float>::infinity();
    mesh.SetVertexPositions(positions);
    ExpectError([&] { mesh.Validate(); }, {"vertex 2", "non-finite position"});

    mesh = TwoTriangles();
    mesh.SetVertexColors(Tensor::FromVector<float>(std::vector<float>(12, 0.5f), {4, 3}));
    EXPECT_NO_THROW(mesh.Validate());
    mesh.GetVertexAttr("colors").Data<float>()[10] = 1.5f;
    ExpectError([&] { mesh.Validate(); }, {"vertex 3", "color channel 1", "outside [0, 1]"});
}

TEST(TriangleMeshTransform, TranslateAndScaleMoveTheBounds) {
    TriangleMesh box = TriangleMesh::CreateBox(1.0, 2.0, 4.0);
    box.Translate(Eigen::Vector3d(1, -1, 0.5));
    EXPECT_EQ(box.GetMinBound(), Eigen::Vector3d(1, -1, 0.5));
    EXPECT_EQ(box.GetMaxBound(), Eigen::Vector3d(2, 1, 4.5));
    box.Translate(Eigen::Vector3d(10, 20, 30), /*relative=*/false);
    EXPECT_TRUE(box.GetCenter().isApprox(Eigen::Vector3d(10, 20, 30), 1e-12));
    EXPECT_EQ(box.GetMinBound(), Eigen::Vector3d(9.5, 19, 28));

    TriangleMesh scaled = TriangleMesh::CreateBox(1.0, 2.0, 4.0);
    scaled.Scale(3.0, Eigen::Vector3d(1, 0, 0));  // p' = 3 (p - c) + c
    EXPECT_EQ(scaled.GetMinBound(), Eigen::Vector3d(-2, 0, 0));
    EXPECT_EQ(scaled.GetMaxBound(), Eigen::Vector3d(1, 6, 12));
    EXPECT_EQ(scaled.GetVertexNormals(), TriangleMesh::CreateBox().GetVertexNormals());
    EXPECT_THROW(scaled.Translate(Eigen::Vector3d(std::nan(""), 0, 0)), core::Open3DError);
}

TEST(TriangleMeshTransform, RotateTurnsNormalsWithThePositions) {
    const TriangleMesh before = TriangleMesh::CreateBox(1.0, 2.0, 3.0);
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    const Eigen::Vector3d center(0.5, 1.0, 1.5);
    TriangleMesh after = before;
    after.Rotate(R, center);
    for (int64_t i = 0; i < before.NumVertices(); ++i) {
        const Eigen::Vector3d p = R * (Row(before.GetVertexPositions(), i) - center) + center;
        EXPECT_LT((Row(after.GetVertexPositions(), i) - p).norm(), 1e-6);
        const Eigen::Vector3d n = R * Row(before.GetVertexNormals(), i);
        EXPECT_LT((Row(after.GetVertexNormals(), i) - n).norm(), 1e-6);
    }
    EXPECT_EQ(after.GetTriangleIndices(), before.GetTriangleIndices());
    EXPECT_GT(MinOutwardness(after, center), 0.0);
    // A non-orthonormal matrix is refused and changes nothing.
    TriangleMesh refused = before;
    EXPECT_THROW(refused.Rotate(2.0 * R, center), core::Open3DError);
    EXPECT_EQ(refused, before);
}

TEST(TriangleMeshTransform, NormalsFollowTheInverseTranspose) {
    // A sphere under diag(a, b, c) becomes the ellipsoid x^2/a^2 + y^2/b^2 + z^2/c^2 = 1,
    // whose exact normal at p is normalize(p.x/a^2, p.y/b^2, p.z/c^2): the normals of the
    // sphere must land there, not at A n.
    const Eigen::Vector3d abc(2.0, 0.5, 1.0), t(3, -2, 1);
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner<3, 3>() = abc.asDiagonal();
    T.topRightCorner<3, 1>() = t;
    TriangleMesh mesh = TriangleMesh::CreateSphere(1.0, 24);
    mesh.Transform(T);
    double max_error = 0.0;
    for (int64_t i = 0; i < mesh.NumVertices(); ++i) {
        const Eigen::Vector3d p = Row(mesh.GetVertexPositions(), i) - t;
        const Eigen::Vector3d exact = p.cwiseQuotient(abc.cwiseProduct(abc)).normalized();
        max_error = std::max(max_error, (Row(mesh.GetVertexNormals(), i) - exact).norm());
    }
    // The reference is built from float positions (rounding <= 2^-24 relative, stretched up to
    // a/b = 4 by the anisotropy) and the result is a float normal; measured 6.7e-7.
    EXPECT_LT(max_error, 2e-6);
    EXPECT_GT(MinOutwardness(mesh, t), 0.0);
    EXPECT_NEAR(mesh.GetMinBound().x(), t.x() - abc.x(), 1e-6);
    EXPECT_NEAR(mesh.GetMaxBound().z(), t.z() + abc.z(), 1e-6);
}

TEST(TriangleMeshTransform, MirrorsKeepTrianglesFacingOutward) {
    Eigen::Matrix4d mirror = Eigen::Matrix4d::Identity();
    mirror(0, 0) = -1.0;
    TriangleMesh mirrored = TriangleMesh::CreateSphere(1.0, 12);
    mirrored.Transform(mirror);
    TriangleMesh inverted = TriangleMesh::CreateSphere(1.0, 12);
    inverted.Scale(-2.0, Eigen::Vector3d::Zero());
    for (TriangleMesh* mesh : {&mirrored, &inverted}) {
        EXPECT_GT(MinOutwardness(*mesh, Eigen::Vector3d::Zero()), 0.0);
        // Normals stay outward radials and agree with the normals the winding implies.
        TriangleMesh recomputed = *mesh;
        recomputed.ComputeVertexNormals();
        for (int64_t i = 0; i < mesh->NumVertices(); ++i) {
            const Eigen::Vector3d radial = Row(mesh->GetVertexPositions(), i).normalized();
            EXPECT_LT((Row(mesh->GetVertexNormals(), i) - radial).norm(), 1e-6);
            EXPECT_GT(Row(recomputed.GetVertexNormals(), i).dot(radial), 0.99);
        }
    }
}

TEST(TriangleMeshTransform, SingularMatricesNeedTheNormalsRemoved) {
    const TriangleMesh box = TriangleMesh::CreateBox();
    TriangleMesh flattened = box;
    ExpectError([&] { flattened.Scale(0.0, Eigen::Vector3d::Zero()); }, {"singular", "normals"});
    EXPECT_EQ(flattened, box);
    Eigen::Matrix4d projection = Eigen::Matrix4d::Identity();
    projection(2, 2) = 0.0;
    flattened.RemoveVertexAttr("normals");
    flattened.Transform(projection);
    EXPECT_EQ(flattened.GetMaxBound(), Eigen::Vector3d(1, 1, 0));
    Eigen::Matrix4d projective = Eigen::Matrix4d::Identity();
    projective(3, 0) = 0.1;
    EXPECT_THROW(flattened.Transform(projective), core::Open3DError);
}

TEST(TriangleMeshNormals, AreAreaWeighted) {
    // Vertex 0 is shared by a triangle of area 0.5 facing +z and one of area 1.5 facing +x.
    const Tensor positions =
        Tensor::FromVector<float>({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 3, 0, 0, 0, 1}, {5, 3});
    TriangleMesh mesh(positions, {{0, 1, 2}, {0, 3, 4}});
    mesh.ComputeVertexNormals();
    const Eigen::Vector3d expected = Eigen::Vector3d(1.5, 0, 0.5).normalized();
    EXPECT_LT((Row(mesh.GetVertexNormals(), 0) - expected).norm(), 1e-7);
    EXPECT_LT((Row(mesh.GetVertexNormals(), 1) - Eigen::Vector3d(0, 0, 1)).norm(), 1e-7);
    EXPECT_LT((Row(mesh.GetVertexNormals(), 4) - Eigen::Vector3d(1, 0, 0)).norm(), 1e-7);

    // An unreferenced vertex gets a zero normal rather than NaN.
    TriangleMesh loose(positions, {{0, 1, 2}});
    loose.ComputeVertexNormals();
    EXPECT_EQ(Row(loose.GetVertexNormals(), 3), Eigen::Vector3d::Zero());
    EXPECT_NO_THROW(loose.Validate());
}

TEST(TriangleMeshNormals, ApproachTheSphereNormals) {
    // Area-weighted normals of the UV sphere converge to the radials at first order in 1/R:
    // the worst vertices sit on the rings next to the poles, where the pole fan and the
    // one-sided quad diagonals make the neighbourhood asymmetric. Measured R * max angle:
    // 0.561 (R = 10), 0.534 (20), 0.526 (40), 0.525 (80).
    for (int res : {10, 20, 40, 80}) {
        TriangleMesh sphere = TriangleMesh::CreateSphere(1.0, res);
        const Tensor exact = sphere.GetVertexNormals();
        sphere.ComputeVertexNormals();
        double max_angle = 0.0;
        for (int64_t i = 0; i < sphere.NumVertices(); ++i) {
            const double cosine = Row(sphere.GetVertexNormals(), i).dot(Row(exact, i));
            max_angle = std::max(max_angle, std::acos(std::min(1.0, cosine)));
        }
        EXPECT_LT(max_angle, 0.6 / res) << res;
        EXPECT_GT(max_angle, 0.4 / res) << res;  // the error really is first order
    }
}

TEST(TriangleMeshColors, PaintUniformColor) {
    TriangleMesh mesh = TwoTriangles();
    EXPECT_FALSE(mesh.HasVertexColors());
    mesh.PaintUniformColor(Eigen::Vector3d(0.25, 0.5, 1.0));
    ASSERT_TRUE(mesh.HasVertexColors());
    for (int64_t i = 0; i < mesh.NumVertices(); ++i) {
        EXPECT_EQ(Row(mesh.GetVertexColors(), i), Eigen::Vector3d(0.25, 0.5, 1.0));
    }
    EXPECT_THROW(mesh.PaintUniformColor(Eigen::Vector3d(0, 1.1, 0)), core::Open3DError);
    EXPECT_THROW(TriangleMesh().PaintUniformColor(Eigen::Vector3d(0, 0, 0)), core::Open3DError);
}

}  // namespace
}  // namespace geometry
}  // namespace t
}  // namespace open3d
