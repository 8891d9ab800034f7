// glTF 2.0 with KHR_gaussian_splatting (Release Candidate, KhronosGroup/glTF 77b44be7): the
// reader of .gltf (external or base64 data-URI buffers) and .glb. The container, buffers and
// accessors are GltfDocument.cpp; the writer is GltfWriter.cpp.
//
// What is read:
// - Every primitive with the extension in the scene (`scene`, else scene 0; without scenes
//   the root nodes; without nodes every mesh once), appended in node order. Other
//   primitives are skipped with a warning. mode must be POINTS (0).
// - Attributes of the current spec: POSITION (float; integers as KHR_mesh_quantization
//   allows), :ROTATION (x y z w: float, byte/short normalised), :SCALE (linear: float,
//   ubyte/ushort, normalised or not; negative refused), :OPACITY (linear alpha: float,
//   ubyte/ushort normalised; stored here as its logit, outside [0, 1] clamped with a
//   warning), :SH_DEGREE_0_COEF_0 = f_dc and :SH_DEGREE_l_COEF_n = f_rest[l^2 + n - 1]
//   (float; the spec's basis, order and signs are those of 3DGS). kernel and colorSpace are
//   required; an unknown kernel reads as ellipse and a colorSpace other than
//   srgb_rec709_display keeps the values as stored, each with a warning.
// - The early draft (the extension object without `kernel`, attributes _SCALE and _ROTATION,
//   none prefixed): POSITION, COLOR_0 VEC4 (float or normalised ubyte/ushort; f_dc =
//   (rgb - 0.5) / C0, opacity = logit(alpha)), _SCALE float VEC3 linear, _ROTATION float
//   VEC4 x y z w, SH degree 0. Read with a warning naming the current attributes.
// - Axes: the spec puts splats in the node's local glTF frame (+Y up, front +Z) and their
//   global mean, covariance and SH follow the node's global transform. That transform is
//   applied (any node hierarchy, matrix or TRS) when it is what the spec calls decomposable,
//   a rotation times a positive (possibly non-uniform) scale plus a translation; the spec
//   leaves other transforms undefined: refused. Then glTF -> RDF (GltfCommon.h). Without a
//   node transform the change is sign flips only, exact. Under a non-uniform scale the
//   covariance L Sigma L^T is diagonalised again (rotation, scale) and the SH follow the
//   rotation component, as the spec says.
// - Primitives compressed with the draft KHR_spz_gaussian_splats_compression (with or without
//   KHR_gaussian_splatting beside it): GltfSpz.cpp, then placed as above.

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <optional>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/geometry/SHRotation.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/GltfCommon.h"
#include "open3d/t/io/GltfDocument.h"
#include "open3d/t/io/GltfPrimitive.h"
#include "open3d/t/io/SplatColumns.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using namespace gltf;

// A node matrix is decomposable (rotation times positive scale) within this error, and its
// scale uniform within this relative error.
constexpr double kDecomposeTolerance = 1e-6;

struct Instance {
    int64_t node = -1;  // -1: a mesh read without a scene graph
    uint64_t mesh = 0;
    Eigen::Matrix4d global = Eigen::Matrix4d::Identity();
};

// Reads the splat primitives of a document's scene into one cloud.
class SceneReader {
public:
    SceneReader(const std::string& filename, ReadPointCloudReport& report)
        : doc_(filename, report) {}
    geometry::PointCloud Read(const ReadPointCloudOptions& options, ReadPointCloudReport& report);

private:
    template <typename... Args>
    [[noreturn]] void Fail(fmt::format_string<Args...> format, Args&&... args) const {
        doc_.Fail(format, std::forward<Args>(args)...);
    }
    const Json* Find(const Json& o, const char* key) const { return doc_.Find(o, key); }
    uint64_t Uint(const Json& o, const char* key, const std::string& where,
                  std::optional<uint64_t> fallback = std::nullopt) const {
        return doc_.Uint(o, key, where, fallback);
    }

    std::vector<Instance> FindInstances();
    Eigen::Matrix4d LocalMatrix(const Json& node, uint64_t index) const;
    bool ReadPrimitive(const Json& primitive, const std::string& where, PrimitiveData& out,
                       ReadPointCloudReport& report);
    void Place(PrimitiveData& d, const Eigen::Matrix4d& global, const std::string& where) const;

    GltfDocument doc_;
};

Eigen::Matrix4d SceneReader::LocalMatrix(const Json& node, uint64_t index) const {
    const std::string what = fmt::format("node {}", index);
    const auto numbers = [&](const char* key, size_t n, std::vector<double> fallback) {
        const Json* v = Find(node, key);
        if (v == nullptr) return fallback;
        if (!v->is_array() || v->size() != n) Fail("{}: '{}' is not {} numbers", what, key, n);
        std::vector<double> out;
        for (const Json& x : *v) out.push_back(doc_.Number(x, what + " " + key));
        return out;
    };
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    if (Find(node, "matrix") != nullptr) {
        const std::vector<double> v = numbers("matrix", 16, {});
        for (int c = 0; c < 4; ++c) {
            for (int r = 0; r < 4; ++r) m(r, c) = v[c * 4 + r];  // column-major
        }
        if (m.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
            Fail("{}: matrix has last row ({}, {}, {}, {}), not (0, 0, 0, 1)", what, m(3, 0),
                 m(3, 1), m(3, 2), m(3, 3));
        }
        return m;
    }
    const std::vector<double> t = numbers("translation", 3, {0, 0, 0});
    const std::vector<double> q = numbers("rotation", 4, {0, 0, 0, 1});  // x, y, z, w
    const std::vector<double> s = numbers("scale", 3, {1, 1, 1});
    const Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
    if (rotation.norm() == 0.0) Fail("{}: rotation is the zero quaternion", what);
    m.topLeftCorner<3, 3>() =
        rotation.normalized().toRotationMatrix() * Eigen::Vector3d(s[0], s[1], s[2]).asDiagonal();
    m.topRightCorner<3, 1>() = Eigen::Vector3d(t[0], t[1], t[2]);
    return m;
}

std::vector<Instance> SceneReader::FindInstances() {
    const Json* nodes = Find(doc_.Root(), "nodes");
    const size_t num_nodes = nodes != nullptr && nodes->is_array() ? nodes->size() : 0;
    // The node indices of a "children" or scene "nodes" list (absent: none).
    const auto indices = [&](const Json* list, const std::string& where) {
        std::vector<uint64_t> out;
        if (list == nullptr) return out;
        if (!list->is_array()) Fail("{}: its node list is not an array", where);
        for (const Json& c : *list) {
            if (!c.is_number_unsigned() || c.get<uint64_t>() >= num_nodes) {
                Fail("{}: child {} is not a node index below {}", where, BriefJson(c), num_nodes);
            }
            out.push_back(c.get<uint64_t>());
        }
        return out;
    };
    std::vector<uint64_t> roots;
    const Json* scenes = Find(doc_.Root(), "scenes");
    if (scenes != nullptr && scenes->is_array() && !scenes->empty()) {
        const uint64_t scene = Uint(doc_.Root(), "scene", "the glTF", 0);
        const Json& s = doc_.Element("scenes", scene, "'scene'");
        roots = indices(Find(s, "nodes"), fmt::format("scene {}", scene));
    } else if (num_nodes > 0) {
        std::vector<bool> is_child(num_nodes, false);
        for (size_t i = 0; i < num_nodes; ++i) {
            const std::string where = fmt::format("node {}", i);
            for (uint64_t c : indices(Find((*nodes)[i], "children"), where)) is_child[c] = true;
        }
        for (size_t i = 0; i < num_nodes; ++i) {
            if (!is_child[i]) roots.push_back(i);
        }
    } else {
        // No scene graph at all: every mesh once, untransformed.
        const Json* meshes = Find(doc_.Root(), "meshes");
        std::vector<Instance> out;
        for (size_t m = 0; meshes != nullptr && meshes->is_array() && m < meshes->size(); ++m) {
            out.push_back({-1, m, Eigen::Matrix4d::Identity()});
        }
        return out;
    }
    std::vector<Instance> out;
    std::vector<bool> visited(num_nodes, false);
    std::vector<std::pair<uint64_t, Eigen::Matrix4d>> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) {
        stack.emplace_back(*it, Eigen::Matrix4d::Identity());
    }
    while (!stack.empty()) {
        const auto [index, parent] = stack.back();
        stack.pop_back();
        const std::string where = fmt::format("node {}", index);
        if (visited[index]) Fail("{} is reached twice: the node hierarchy is not a tree", where);
        visited[index] = true;
        const Json& node = (*nodes)[index];
        if (!node.is_object()) Fail("{} is not an object", where);
        const Eigen::Matrix4d global = parent * LocalMatrix(node, index);
        if (Find(node, "mesh") != nullptr) {
            out.push_back({int64_t(index), Uint(node, "mesh", where), global});
        }
        const std::vector<uint64_t> kids = indices(Find(node, "children"), where);
        for (auto it = kids.rbegin(); it != kids.rend(); ++it) stack.emplace_back(*it, global);
    }
    return out;
}

// Reads one primitive that carries either extension; false for any other primitive.
bool SceneReader::ReadPrimitive(const Json& primitive, const std::string& where, PrimitiveData& d,
                                ReadPointCloudReport& report) {
    const Json* extensions = Find(primitive, "extensions");
    // The SPZ holds every value, whatever KHR_gaussian_splatting beside it says.
    if (const Json* spz = extensions != nullptr ? Find(*extensions, kSpzExtension) : nullptr) {
        ReadSpzPrimitive(doc_, primitive, *spz, where, d, report);
        return true;
    }
    const Json* ext = extensions != nullptr ? Find(*extensions, kExtension) : nullptr;
    if (ext == nullptr) return false;
    if (!ext->is_object()) Fail("{}: {} is not an object", where, kExtension);
    const Json* attributes = Find(primitive, "attributes");
    if (attributes == nullptr || !attributes->is_object()) Fail("{} has no attributes", where);
    const uint64_t mode = Uint(primitive, "mode", where, 4);
    if (mode != 0) Fail("{} has mode {}; Gaussian splats are POINTS (mode 0)", where, mode);
    if (const Json* nested = Find(*ext, "extensions"); nested != nullptr && nested->is_object()) {
        for (const auto& [name, value] : nested->items()) {
            if (name.rfind("KHR_gaussian_splatting_compression", 0) == 0) {
                Fail("{} is compressed with {}, which this reader does not decode", where, name);
            }
        }
    }
    bool has_current = false;
    for (const auto& [name, value] : attributes->items()) {
        has_current = has_current || name.rfind(kAttributePrefix, 0) == 0;
    }
    // The early draft: no kernel, "_SCALE" / "_ROTATION" and COLOR_0 (rgb + alpha = opacity).
    const bool draft =
        !has_current && Find(*ext, "kernel") == nullptr &&
        (Find(*attributes, "_SCALE") != nullptr || Find(*attributes, "_ROTATION") != nullptr);
    if (draft) {
        core::LogWarning(
            "'{}': {} follows an early draft of {} (COLOR_0 with alpha as opacity, _SCALE, "
            "_ROTATION); read as such. The current extension has kernel, colorSpace and "
            "the {}SCALE/ROTATION/OPACITY/SH_DEGREE_l_COEF_n attributes",
            doc_.Filename(), where, kExtension, kAttributePrefix);
    } else {
        const std::string ext_where = where + " " + kExtension;
        const std::string kernel = doc_.String(*ext, "kernel", ext_where);
        const std::string color_space = doc_.String(*ext, "colorSpace", ext_where);
        if (kernel != "ellipse") {
            core::LogWarning("'{}': {}: kernel '{}' is unknown, read as 'ellipse'", doc_.Filename(),
                             where, kernel);
        }
        if (color_space != "srgb_rec709_display") {
            core::LogWarning(
                "'{}': {}: colorSpace '{}'; the SH values are kept as stored "
                "(3DGS colours are usually srgb_rec709_display)",
                doc_.Filename(), where, color_space);
        }
    }
    const auto attribute = [&](const std::string& name) {
        if (Find(*attributes, name.c_str()) == nullptr) {
            Fail("{} has no {} attribute ({}){}", where, name,
                 draft ? "required by the early draft of KHR_gaussian_splatting"
                       : "required by KHR_gaussian_splatting",
                 draft ? ""
                       : "; required: POSITION, :SCALE, :ROTATION, :OPACITY, "
                         ":SH_DEGREE_0_COEF_0");
        }
        return Uint(*attributes, name.c_str(), where + " attributes");
    };
    const std::string p = kAttributePrefix;
    const std::string scale_name = draft ? "_SCALE" : p + "SCALE";
    const std::string rot_name = draft ? "_ROTATION" : p + "ROTATION";
    const uint64_t position_index = attribute("POSITION");
    const uint64_t scale_index = attribute(scale_name);
    const uint64_t rot_index = attribute(rot_name);
    const uint64_t color_index = attribute(draft ? "COLOR_0" : p + "SH_DEGREE_0_COEF_0");
    const uint64_t opacity_index = draft ? 0 : attribute(p + "OPACITY");
    // SH degrees: complete, and each one needs every lower one.
    int degree = 0;
    std::vector<uint64_t> sh_indices;
    for (int l = 1; l <= 3 && !draft; ++l) {
        std::vector<int> present, absent;
        for (int n = 0; n < 2 * l + 1; ++n) {
            (Find(*attributes, ShAttributeName(l, n).c_str()) ? present : absent).push_back(n);
        }
        if (present.empty()) continue;
        if (!absent.empty()) {
            Fail(
                "{}: SH degree {} is partly defined: {} is missing (a degree needs all {} "
                "coefficients)",
                where, l, ShAttributeName(l, absent[0]), 2 * l + 1);
        }
        if (degree != l - 1) {
            Fail("{} has SH degree {} but not degree {} ({} is missing)", where, l, l - 1,
                 ShAttributeName(l - 1, 0));
        }
        degree = l;
        for (int n = 0; n < 2 * l + 1; ++n) sh_indices.push_back(attribute(ShAttributeName(l, n)));
    }

    const std::vector<Allowed> kFloat = {{kComponentFloat, false}};
    const std::vector<Allowed> position_types = {
        {kComponentFloat, false},       {kComponentByte, false},
        {kComponentByte, true},         {kComponentUnsignedByte, false},
        {kComponentUnsignedByte, true}, {kComponentShort, false},
        {kComponentShort, true},        {kComponentUnsignedShort, false},
        {kComponentUnsignedShort, true}};  // integers: KHR_mesh_quantization
    d.positions = doc_.DecodeAccessor(position_index, "POSITION", 3, position_types, -1);
    const int64_t n = static_cast<int64_t>(d.positions.size() / 3);
    d.n = n;
    d.degree = degree;
    d.scale = doc_.DecodeAccessor(scale_index, scale_name, 3,
                                  draft ? kFloat
                                        : std::vector<Allowed>{{kComponentFloat, false},
                                                               {kComponentUnsignedByte, false},
                                                               {kComponentUnsignedByte, true},
                                                               {kComponentUnsignedShort, false},
                                                               {kComponentUnsignedShort, true}},
                                  n);
    for (int64_t k = 0; k < n * 3; ++k) {
        if (d.scale[k] < 0.0f) {
            Fail("{}: {} of splat {} is negative ({}); scales must not be negative", where,
                 scale_name, k / 3, d.scale[k]);
        }
    }
    const std::vector<float> xyzw =
        doc_.DecodeAccessor(rot_index, rot_name, 4,
                            draft ? kFloat
                                  : std::vector<Allowed>{{kComponentFloat, false},
                                                         {kComponentByte, true},
                                                         {kComponentShort, true}},
                            n);
    d.rot.resize(n * 4);
    for (int64_t i = 0; i < n; ++i) {
        d.rot[i * 4 + 0] = xyzw[i * 4 + 3];
        for (int c = 0; c < 3; ++c) d.rot[i * 4 + 1 + c] = xyzw[i * 4 + c];
    }
    d.opacity.resize(n);
    d.f_dc.resize(n * 3);
    int64_t clamped = 0;
    const auto opacity = [&](int64_t i, float alpha) {
        if (alpha < 0.0f || alpha > 1.0f) ++clamped;
        d.opacity[i] = std::isnan(alpha) ? alpha : DecodeOpacity(alpha);
    };
    if (draft) {
        const std::vector<float> rgba = doc_.DecodeAccessor(color_index, "COLOR_0", 4,
                                                            {{kComponentFloat, false},
                                                             {kComponentUnsignedByte, true},
                                                             {kComponentUnsignedShort, true}},
                                                            n);
        for (int64_t i = 0; i < n; ++i) {
            for (int c = 0; c < 3; ++c) {
                d.f_dc[i * 3 + c] = float((rgba[i * 4 + c] - 0.5) / geometry::kSH_C0);
            }
            opacity(i, rgba[i * 4 + 3]);
        }
    } else {
        d.f_dc = doc_.DecodeAccessor(color_index, p + "SH_DEGREE_0_COEF_0", 3, kFloat, n);
        const std::vector<float> alpha = doc_.DecodeAccessor(opacity_index, p + "OPACITY", 1,
                                                             {{kComponentFloat, false},
                                                              {kComponentUnsignedByte, true},
                                                              {kComponentUnsignedShort, true}},
                                                             n);
        for (int64_t i = 0; i < n; ++i) opacity(i, alpha[i]);
    }
    if (clamped > 0) {
        core::LogWarning("'{}': {}: {} opacities outside [0, 1] clamped", doc_.Filename(), where,
                         clamped);
    }
    const int nc = geometry::NumSHRestCoeffs(degree);
    d.f_rest.assign(n * nc * 3, 0.0f);
    for (int k = 0; k < nc; ++k) {
        const int l = int(std::sqrt(double(k + 1)));
        const std::vector<float> v =
            doc_.DecodeAccessor(sh_indices[k], ShAttributeName(l, k + 1 - l * l), 3, kFloat, n);
        for (int64_t i = 0; i < n; ++i) {
            std::copy_n(&v[i * 3], 3, &d.f_rest[(i * nc + k) * 3]);
        }
    }
    return true;
}

// glTF local frame -> RDF world: x_world = C (M x + t), C = diag(1, -1, -1) (GltfCommon.h).
void SceneReader::Place(PrimitiveData& d, const Eigen::Matrix4d& global,
                        const std::string& where) const {
    const Eigen::Matrix3d M = global.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = global.topRightCorner<3, 1>();
    const Eigen::Matrix3d C = Eigen::Vector3d(1, -1, -1).asDiagonal();
    const Eigen::Vector3d b = C * t;
    const int nc = geometry::NumSHRestCoeffs(d.degree);
    if (M == Eigen::Matrix3d::Identity()) {  // exact: sign flips (and one rounding for t)
        const bool translate = t != Eigen::Vector3d::Zero();
        core::ParallelFor(d.n, [&](int64_t i) {
            float* p = &d.positions[i * 3];
            p[1] = -p[1];
            p[2] = -p[2];
            for (int c = 0; c < 3 && translate; ++c) p[c] = float(double(p[c]) + b[c]);
            d.rot[i * 4 + 2] = -d.rot[i * 4 + 2];
            d.rot[i * 4 + 3] = -d.rot[i * 4 + 3];
            for (int k = 0; k < nc; ++k) {
                for (int c = 0; c < 3; ++c) d.f_rest[(i * nc + k) * 3 + c] *= kShSignRdf[k];
            }
        });
        return;
    }
    // The spec's decomposable transforms: M = R diag(s) with R a rotation and s > 0.
    const Eigen::Vector3d lengths(M.col(0).norm(), M.col(1).norm(), M.col(2).norm());
    const Eigen::Matrix3d R = M * lengths.cwiseInverse().asDiagonal();
    const bool rotation = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <=
                          kDecomposeTolerance;
    if (!global.allFinite() || !(lengths.minCoeff() > 0) || !rotation || !(R.determinant() > 0)) {
        Fail(
            "{}: its node's global transform is not a rotation times a positive scale "
            "(column lengths {:.6g}, {:.6g}, {:.6g}, det {:.6g}); KHR_gaussian_splatting leaves "
            "splats under it undefined, they are not read",
            where, lengths[0], lengths[1], lengths[2], M.determinant());
    }
    const double s = lengths.mean();
    const bool uniform = (lengths.array() - s).abs().maxCoeff() <= kDecomposeTolerance * s;
    const Eigen::Matrix3d rotation_rdf = C * R;
    const Eigen::Matrix3d linear = C * M;
    const Eigen::Quaterniond q_r = Eigen::Quaterniond(rotation_rdf).normalized();
    const geometry::SHRotation sh(rotation_rdf, d.degree);  // the spec: SH follow R only
    core::ParallelFor(d.n, [&](int64_t i) {
        float* p = &d.positions[i * 3];
        const Eigen::Vector3d x = linear * Eigen::Vector3d(p[0], p[1], p[2]) + b;
        for (int c = 0; c < 3; ++c) p[c] = float(x[c]);
        float* q = &d.rot[i * 4];
        float* scale = &d.scale[i * 3];
        if (uniform) {  // Sigma' = s^2 (R R_q) S^2 (R R_q)^T: q' = q_R * q, scale * s
            const Eigen::Quaterniond r = q_r * Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
            q[0] = float(r.w()), q[1] = float(r.x()), q[2] = float(r.y()), q[3] = float(r.z());
            for (int c = 0; c < 3; ++c) scale[c] = float(scale[c] * s);
        } else if (q[0] != 0 || q[1] != 0 || q[2] != 0 || q[3] != 0) {
            // Sigma' = L Sigma L^T, L = C M, diagonalised again into (rotation, scale). A zero
            // quaternion is left for FinalizeColumns to report.
            const Eigen::Matrix3d rq =
                Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
            const Eigen::Matrix3d axes =
                linear * rq * Eigen::Vector3d(scale[0], scale[1], scale[2]).asDiagonal();
            const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(axes * axes.transpose());
            Eigen::Matrix3d v = eigen.eigenvectors();
            if (v.determinant() < 0) v.col(0) = -v.col(0);
            const Eigen::Quaterniond r(v);
            q[0] = float(r.w()), q[1] = float(r.x()), q[2] = float(r.y()), q[3] = float(r.z());
            for (int c = 0; c < 3; ++c) {
                scale[c] = float(std::sqrt(std::max(eigen.eigenvalues()[c], 0.0)));
            }
        }
        if (nc > 0) sh.Apply(&d.f_rest[i * nc * 3]);
    });
}

geometry::PointCloud SceneReader::Read(const ReadPointCloudOptions& options,
                                       ReadPointCloudReport& report) {
    std::vector<PrimitiveData> parts;
    int64_t total = 0, ignored = 0;
    int degree = 0;
    for (const Instance& instance : FindInstances()) {
        const std::string mesh_where = fmt::format("mesh {}", instance.mesh);
        const Json& mesh = doc_.Element(
            "meshes", instance.mesh,
            instance.node < 0 ? std::string("the glTF") : fmt::format("node {}", instance.node));
        const Json* primitives = Find(mesh, "primitives");
        if (primitives == nullptr || !primitives->is_array()) {
            Fail("{} has no primitives array", mesh_where);
        }
        for (size_t k = 0; k < primitives->size(); ++k) {
            const std::string where = fmt::format("{} primitive {}", mesh_where, k);
            PrimitiveData d;
            if (!ReadPrimitive((*primitives)[k], where, d, report)) {
                ++ignored;
                continue;
            }
            total += d.n;
            // Instancing could multiply the splats of a small file without bound.
            if (uint64_t(total) > doc_.InputBytes()) {
                Fail("{}: the scene instantiates more splats than the input has bytes ({})", where,
                     doc_.InputBytes());
            }
            Place(d, instance.global,
                  instance.node < 0 ? where : fmt::format("{} (node {})", where, instance.node));
            degree = std::max(degree, d.degree);
            parts.push_back(std::move(d));
        }
    }
    if (parts.empty()) {
        Fail(
            "no mesh primitive of the scene has the {} or {} extension (a plain glTF mesh or "
            "point cloud is not a Gaussian splat file)",
            kExtension, kSpzExtension);
    }
    if (ignored > 0) {
        core::LogWarning("'{}': {} mesh primitives without {} or {} are ignored", doc_.Filename(),
                         ignored, kExtension, kSpzExtension);
    }
    SplatColumns columns;
    columns.Allocate(doc_.Filename(), total, /*gaussian=*/true, degree);
    const int nc = geometry::NumSHRestCoeffs(degree);
    float* f_rest = columns.f_rest.NumBytes() > 0 ? columns.f_rest.Data<float>() : nullptr;
    int64_t start = 0;
    for (PrimitiveData& d : parts) {
        std::copy(d.positions.begin(), d.positions.end(),
                  columns.positions.Data<float>() + start * 3);
        std::copy(d.rot.begin(), d.rot.end(), columns.rot.Data<float>() + start * 4);
        std::copy(d.scale.begin(), d.scale.end(), columns.scale.Data<float>() + start * 3);
        std::copy(d.opacity.begin(), d.opacity.end(), columns.opacity.Data<float>() + start);
        std::copy(d.f_dc.begin(), d.f_dc.end(), columns.f_dc.Data<float>() + start * 3);
        const int own = geometry::NumSHRestCoeffs(d.degree);  // lower degrees: zero padded
        for (int64_t i = 0; i < d.n && nc > 0; ++i) {
            float* row = f_rest + (start + i) * nc * 3;
            std::fill_n(row, nc * 3, 0.0f);
            std::copy_n(d.f_rest.data() + i * own * 3, own * 3, row);
        }
        start += d.n;
        d = PrimitiveData();
    }
    return FinalizeColumns(doc_.Filename(), columns, options, report);
}

}  // namespace

geometry::PointCloud ReadGltf(const std::string& filename, const ReadPointCloudOptions& options,
                              ReadPointCloudReport& report) {
    try {
        SceneReader reader(filename, report);
        return reader.Read(options, report);
    } catch (const nlohmann::json::exception& e) {  // a JSON access this reader did not guard
        core::ThrowError("'{}': malformed glTF JSON: {}", filename, e.what());
    }
}

}  // namespace io
}  // namespace t
}  // namespace open3d
