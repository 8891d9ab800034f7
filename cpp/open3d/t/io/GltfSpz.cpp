// glTF KHR_spz_gaussian_splats_compression, the draft that stores a primitive's splats as one
// SPZ blob: CesiumGS/glTF branch draft-spz-splat-compression (README and schema), revised in
// CesiumGS/glTF pull request 86 to sit beside an empty KHR_gaussian_splatting object on the
// same primitive. The shape:
//   "mode": 0, "attributes": {"POSITION": 0, "COLOR_0": 1, "_SCALE": 2, "_ROTATION": 3,
//                             "_SH_DEGREE_1_COEF_0": 4, ...},
//   "extensions": {"KHR_spz_gaussian_splats_compression": {"bufferView": 5}}
// The accessors of those attributes have no bufferView: they name what the SPZ holds, with the
// decoded type, and their count must be the SPZ's splat count.
//
// What is read:
// - The SPZ in the extension's bufferView, decoded by the SPZ reader (DecodeSpz: every check
//   a .spz file gets, v1-v4). It supplies every value; an accessor's bufferView, byteOffset or
//   sparse is ignored with a warning (the first draft says to ignore them, the revision
//   forbids them). componentType and type are not checked: nothing is read through them, and
//   SharpGLTF's fixture tower.glb declares its SH accessors VEC4 where the draft says VEC3.
// - POSITION, COLOR_0, _ROTATION and _SCALE are required; colour (SH_DEGREE_0_COEF_0),
//   rotation, scale and SH are also taken under the KHR_gaussian_splatting: names, which
//   CesiumJS maps into the SPZ too.
//   The SH degrees named must be complete and at most the SPZ's; a higher SPZ degree is cut to
//   the degree named, with a warning (CesiumJS loads the named attributes only).
// - Axes: the values are the primitive's glTF coordinates as the SPZ stores them, no axis
//   change. That is what CesiumJS does, the draft authors' loader (GltfSpzLoader.js decodes
//   with spz-loader's coordinateSystem "UNSPECIFIED", which converts nothing; before
//   spz-loader 0.3 it undid that loader's 180-degree turn about x for the positions), and what
//   JSplat's glTF SPZ reader and writer do. The draft's text asks for LUF in the SPZ library's
//   pack or unpack options instead, which negates x and z against SPZ's stored RUB (a
//   180-degree turn about y): files made for CesiumJS would come out turned. glTF's axes are
//   three.js's RUB (+Y up, +Z towards the viewer), so an SPZ read here lands where the same
//   bytes read as a .spz file do, (x, -y, -z) in RDF, before the node's transform, which
//   applies as for KHR_gaussian_splatting (GltfFormat.cpp). SPZ_ADOBE_coordinate_system is
//   ignored with a warning.

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "open3d/core/Logging.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/GltfCommon.h"
#include "open3d/t/io/GltfPrimitive.h"
#include "open3d/t/io/SplatColumns.h"

namespace open3d {
namespace t {
namespace io {
namespace gltf {
namespace {

struct Attribute {
    std::string name;
    uint64_t accessor;
};

// The attribute under its draft name or, absent, its KHR_gaussian_splatting name.
std::optional<Attribute> FindAttribute(const GltfDocument& doc, const Json& attributes,
                                       const std::string& draft, const std::string& current,
                                       const std::string& where) {
    for (const std::string& name : {draft, current}) {
        if (doc.Find(attributes, name.c_str()) != nullptr) {
            return Attribute{name, doc.Uint(attributes, name.c_str(), where + " attributes")};
        }
    }
    return std::nullopt;
}

std::vector<float> TakeFloats(core::Tensor& column) {
    std::vector<float> out;
    if (column.NumElements() > 0) {
        const float* p = column.Data<float>();
        out.assign(p, p + column.NumElements());
    }
    column = core::Tensor();  // one column at a time: the copy never doubles the whole cloud
    return out;
}

}  // namespace

void ReadSpzPrimitive(GltfDocument& doc, const Json& primitive, const Json& extension,
                      const std::string& where, PrimitiveData& d, ReadPointCloudReport& report) {
    const std::string ext_where = where + " " + kSpzExtension;
    if (!extension.is_object()) doc.Fail("{} is not an object", ext_where);
    const Json* base = doc.Find(*doc.Find(primitive, "extensions"), kExtension);
    if (base != nullptr && !base->is_object())
        doc.Fail("{}: {} is not an object", where, kExtension);
    const Json* attributes = doc.Find(primitive, "attributes");
    if (attributes == nullptr || !attributes->is_object()) doc.Fail("{} has no attributes", where);
    const uint64_t mode = doc.Uint(primitive, "mode", where, 4);
    if (mode != 0) doc.Fail("{} has mode {}; Gaussian splats are POINTS (mode 0)", where, mode);

    std::vector<Attribute> named;
    const auto require = [&](const std::string& draft, const std::string& current) {
        const std::optional<Attribute> a = FindAttribute(doc, *attributes, draft, current, where);
        if (!a) {
            doc.Fail(
                "{} has no {} attribute (required by {}: POSITION, COLOR_0, _ROTATION, _SCALE)",
                where, draft, kSpzExtension);
        }
        named.push_back(*a);
    };
    const std::string p = kAttributePrefix;
    require("POSITION", "POSITION");
    require("COLOR_0", p + "SH_DEGREE_0_COEF_0");
    require("_ROTATION", p + "ROTATION");
    require("_SCALE", p + "SCALE");
    if (auto opacity = FindAttribute(doc, *attributes, p + "OPACITY", p + "OPACITY", where)) {
        named.push_back(*opacity);
    }
    // SH degrees: complete, and each one needs every lower one.
    int degree = 0;
    for (int l = 1; l <= 3; ++l) {
        std::vector<Attribute> present;
        std::string absent;
        for (int n = 0; n < 2 * l + 1; ++n) {
            const std::string draft = fmt::format("_SH_DEGREE_{}_COEF_{}", l, n);
            if (auto a = FindAttribute(doc, *attributes, draft, ShAttributeName(l, n), where)) {
                present.push_back(*a);
            } else if (absent.empty()) {
                absent = draft;
            }
        }
        if (present.empty()) continue;
        if (!absent.empty()) {
            doc.Fail(
                "{}: SH degree {} is partly defined: {} is missing (a degree needs all {} "
                "coefficients)",
                where, l, absent, 2 * l + 1);
        }
        if (degree != l - 1) {
            doc.Fail("{} has SH degree {} but not degree {}", where, l, l - 1);
        }
        degree = l;
        named.insert(named.end(), present.begin(), present.end());
    }
    for (const Attribute& a : named) doc.Element("accessors", a.accessor, where + " " + a.name);

    const uint64_t view = doc.Uint(extension, "bufferView", ext_where);
    const Span bytes = doc.BufferView(view, ext_where);
    SplatColumns c;
    DecodeSpz(bytes.data, bytes.size, doc.Filename(),
              fmt::format("'{}': {} (the SPZ in bufferView {})", doc.Filename(), ext_where, view),
              SpzAxes::kAsStored, c, report);
    const int64_t n = c.num_points;

    bool stored_elsewhere = false;
    for (const Attribute& a : named) {
        const std::string what = fmt::format("accessor {} ({})", a.accessor, a.name);
        const Json& accessor = doc.Element("accessors", a.accessor, where + " " + a.name);
        const uint64_t count = doc.Uint(accessor, "count", what);
        if (count != uint64_t(n)) {
            doc.Fail(
                "{} has count {} but the SPZ in bufferView {} holds {} splats ({}: the "
                "counts must match)",
                what, count, view, n, kSpzExtension);
        }
        stored_elsewhere = stored_elsewhere || doc.Find(accessor, "bufferView") != nullptr ||
                           doc.Find(accessor, "byteOffset") != nullptr ||
                           doc.Find(accessor, "sparse") != nullptr;
    }
    if (n == 0) doc.Fail("{}: the SPZ in bufferView {} holds no splats", ext_where, view);
    if (stored_elsewhere) {
        core::LogWarning(
            "'{}': {}: an accessor of an SPZ-compressed attribute has a bufferView, byteOffset "
            "or sparse; ignored, the values come from the SPZ",
            doc.Filename(), where);
    }
    if (degree > c.sh_degree) {
        doc.Fail("{} names SH degree {} ({}), but the SPZ in bufferView {} holds degree {}", where,
                 degree, fmt::format("_SH_DEGREE_{}_COEF_0", degree), view, c.sh_degree);
    }
    if (degree < c.sh_degree) {
        core::LogWarning(
            "'{}': {}: the SPZ holds SH degree {} but the attributes name degree {}; the "
            "higher degrees are dropped",
            doc.Filename(), where, c.sh_degree, degree);
    }

    d.n = n;
    d.degree = degree;
    d.positions = TakeFloats(c.positions);
    d.rot = TakeFloats(c.rot);
    d.scale = TakeFloats(c.scale);
    d.opacity = TakeFloats(c.opacity);
    d.f_dc = TakeFloats(c.f_dc);
    const int nc = geometry::NumSHRestCoeffs(degree),
              stored_nc = geometry::NumSHRestCoeffs(c.sh_degree);
    if (nc == stored_nc) {
        d.f_rest = TakeFloats(c.f_rest);
    } else if (nc > 0) {
        const float* rest = c.f_rest.Data<float>();
        d.f_rest.resize(size_t(n) * nc * 3);
        for (int64_t i = 0; i < n; ++i) {
            std::copy_n(rest + i * stored_nc * 3, nc * 3, d.f_rest.data() + i * nc * 3);
        }
    }
}

}  // namespace gltf
}  // namespace io
}  // namespace t
}  // namespace open3d
