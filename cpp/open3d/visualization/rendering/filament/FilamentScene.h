// What a Filament view draws (docs/filament.md "Scene"): named meshes and plain point clouds
// as Filament renderables, and named Gaussian splat clouds held by a GaussianSplatRenderer
// (merged into one backend scene; showing or hiding one patches the visibility mask only).
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/filament/MaterialRecord.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatRenderer.h"

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

class FilamentScene {
public:
    /// Draws meshes and points with `materials` and splats with `backend` (owned).
    FilamentScene(filament::Engine& engine, const FilamentMaterials& materials,
                  std::unique_ptr<GaussianSplatBackend> backend);
    ~FilamentScene();
    FilamentScene(const FilamentScene&) = delete;
    FilamentScene& operator=(const FilamentScene&) = delete;

    /// Adds a point cloud: through the splat pipeline when `material.shader` is
    /// "gaussianSplat", else as Filament points. Without a material, clouds with the
    /// Gaussian attributes are splats and others points. Throws core::Open3DError when the
    /// name is taken, the shader is unknown, or a "gaussianSplat" cloud lacks the Gaussian
    /// attributes (the scene is unchanged then).
    void AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud);
    void AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud,
                     const MaterialRecord& material);
    /// Adds a triangle mesh ("defaultUnlit" or "defaultLit"). Throws when the name is taken,
    /// the shader does not draw meshes, or the mesh is invalid.
    void AddGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh,
                     const MaterialRecord& material = {});
    /// Replaces a geometry of the same kind with its material and visibility. Throws when
    /// the name is unknown or the kind differs.
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

    /// A visible mesh or point cloud exists: the splat composite must test against the
    /// scene depth.
    bool HasNonGaussianVisibleGeometry() const;
    /// The material a geometry was added with; throws when the name is unknown.
    const MaterialRecord& GetMaterial(const std::string& name) const;

    /// The directional light of "defaultLit" meshes: `direction` points from the light into
    /// the scene, in the world frame or in the camera frame (OpenCV axes: x right, y down,
    /// z forward; the light then follows the camera, as a headlight); `ambient` in [0, 1]
    /// is the light every surface gets. Default: camera frame (0.3, 0.5, 1), from above
    /// left behind the viewer, ambient 0.25.
    enum class LightFrame { kWorld, kCamera };
    void SetLighting(const Eigen::Vector3f& direction, float ambient,
                     LightFrame frame = LightFrame::kWorld);
    /// Points a camera-frame light for `camera` (FilamentRenderer::Draw calls it per view).
    void PrepareLighting(const camera::PinholeCamera& camera);
    /// A visible splat cloud exists: the splat stages must run.
    bool HasVisibleGaussianSplats() const;
    /// Axis-aligned bounds of the visible geometry; false when there is none.
    bool GetBounds(Eigen::Vector3d& min_bound, Eigen::Vector3d& max_bound) const;

    filament::Scene* GetFilamentScene() const { return scene_; }
    /// The splat half of the scene.
    GaussianSplatRenderer& GetSplatRenderer() { return splats_; }
    /// The splat backend, with the merged scene uploaded (call PrepareSplats first).
    GaussianSplatBackend& GetBackend() const { return splats_.GetBackend(); }
    /// Uploads the merged scene or the visibility mask when they changed.
    void PrepareSplats() { splats_.Prepare(); }

    using Counters = GaussianSplatRenderer::Counters;
    const Counters& GetCounters() const { return splats_.GetCounters(); }

private:
    // A Filament renderable: a triangle mesh or a plain point cloud.
    struct Mesh {
        uint32_t entity = 0;  // utils::Entity id
        bool points = false;
        filament::VertexBuffer* vertices = nullptr;
        filament::IndexBuffer* indices = nullptr;
        filament::MaterialInstance* material = nullptr;
        MaterialRecord look;
        Eigen::Vector3d min_bound, max_bound;
        bool visible = true;
    };
    Mesh BuildMesh(const t::geometry::TriangleMesh& mesh, const MaterialRecord& material);
    Mesh BuildPoints(const t::geometry::PointCloud& cloud, const MaterialRecord& material);
    void Finish(Mesh& out, int primitive, size_t num_indices);
    void AddMesh(const std::string& name, Mesh built);
    /// Swaps `old` for `built`, keeping its visibility (its material came from `old`).
    void ReplaceMesh(Mesh& old, Mesh built);
    void DestroyMesh(Mesh& mesh);

    filament::Engine& engine_;
    const FilamentMaterials& materials_;
    GaussianSplatRenderer splats_;
    filament::Scene* scene_ = nullptr;
    std::map<std::string, Mesh> meshes_;
    std::map<std::string, MaterialRecord> cloud_materials_;  // "gaussianSplat" clouds
    Eigen::Vector3f light_direction_{0.3f, 0.5f, 1.0f};      // in light_frame_
    LightFrame light_frame_ = LightFrame::kCamera;
    Eigen::Vector3f world_light_{0.3f, 0.5f, 1.0f};  // the direction the materials hold
    float ambient_ = 0.25f;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
