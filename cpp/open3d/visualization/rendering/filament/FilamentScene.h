// What a Filament view draws (docs/filament.md "Scene"): named meshes as Filament
// renderables and named Gaussian splat clouds merged into one backend scene. Adding,
// removing or updating a cloud rebuilds the merged scene; showing or hiding one patches
// the backend's visibility mask only (no rebuild, see GetCounters).
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"

namespace filament {
class Engine;
class Scene;
class VertexBuffer;
class IndexBuffer;
class MaterialInstance;
}  // namespace filament

namespace open3d {
namespace visualization {
namespace rendering {

class FilamentMaterials;

/// How a mesh is drawn (materials/mesh_unlit.mat).
struct MeshMaterial {
    /// Linear RGBA multiplied with the vertex colours (white when the mesh has none).
    Eigen::Vector4f base_color{0.8f, 0.8f, 0.8f, 1.0f};
    /// 0 = flat colour; up to 1 darkens surfaces turned away from the viewer.
    float shading = 0.0f;
};

class FilamentScene {
public:
    /// Draws meshes with `materials` and splats with `backend` (owned).
    FilamentScene(filament::Engine& engine, const FilamentMaterials& materials,
                  std::unique_ptr<GaussianSplatBackend> backend);
    ~FilamentScene();
    FilamentScene(const FilamentScene&) = delete;
    FilamentScene& operator=(const FilamentScene&) = delete;

    /// Adds a Gaussian splat cloud. Throws core::Open3DError when the name is taken or the
    /// cloud is not a valid splat cloud (the scene is unchanged then).
    void AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud);
    /// Adds a triangle mesh. Throws when the name is taken or the mesh is invalid.
    void AddGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh,
                     const MeshMaterial& material = {});
    /// Replaces a geometry of the same kind (its visibility is kept). Throws when the name
    /// is unknown or the kind differs.
    void UpdateGeometry(const std::string& name, const t::geometry::PointCloud& cloud);
    void UpdateGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh);
    /// Removes a geometry; false when the name is unknown.
    bool RemoveGeometry(const std::string& name);
    /// Shows or hides a geometry; throws when the name is unknown.
    void ShowGeometry(const std::string& name, bool show);
    bool HasGeometry(const std::string& name) const;
    bool IsGeometryVisible(const std::string& name) const;
    std::vector<std::string> GetGeometryNames() const;
    void ClearGeometry();

    /// A visible mesh exists: the splat composite must test against the scene depth.
    bool HasNonGaussianVisibleGeometry() const;
    /// A visible splat cloud exists: the splat stages must run.
    bool HasVisibleGaussianSplats() const;
    /// Axis-aligned bounds of the visible geometry; false when there is none.
    bool GetBounds(Eigen::Vector3d& min_bound, Eigen::Vector3d& max_bound) const;

    filament::Scene* GetFilamentScene() const { return scene_; }
    /// The splat backend, with the merged scene uploaded (call PrepareSplats first).
    GaussianSplatBackend& GetBackend() const { return *backend_; }
    /// Uploads the merged scene or the visibility mask when they changed.
    void PrepareSplats();

    struct Counters {
        int64_t merged_rebuilds = 0;  ///< merged scenes built and uploaded
        int64_t mask_updates = 0;     ///< visibility masks sent without a rebuild
    };
    const Counters& GetCounters() const { return counters_; }

private:
    struct Mesh {
        uint32_t entity = 0;  // utils::Entity id
        filament::VertexBuffer* vertices = nullptr;
        filament::IndexBuffer* indices = nullptr;
        filament::MaterialInstance* material = nullptr;
        MeshMaterial look;
        Eigen::Vector3d min_bound, max_bound;
        bool visible = true;
    };
    struct Cloud {
        t::geometry::PointCloud cloud;
        int64_t first = 0;  ///< index of its first splat in the merged scene
        bool visible = true;
    };

    Mesh BuildMesh(const t::geometry::TriangleMesh& mesh, const MeshMaterial& material);
    void DestroyMesh(Mesh& mesh);
    std::vector<uint32_t> VisibilityMask() const;

    filament::Engine& engine_;
    const FilamentMaterials& materials_;
    std::unique_ptr<GaussianSplatBackend> backend_;
    filament::Scene* scene_ = nullptr;
    std::map<std::string, Mesh> meshes_;
    std::map<std::string, Cloud> clouds_;
    bool merged_dirty_ = false;     // clouds added, removed or replaced
    bool mask_dirty_ = false;       // a cloud shown or hidden
    bool merged_uses_mask_ = true;  // false: the backend has no mask; hidden clouds left out
    Counters counters_;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
