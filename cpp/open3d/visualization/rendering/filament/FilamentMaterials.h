// The materials the Filament layer draws with (materials/*.mat, compiled by matc at build
// time and embedded), loaded once per engine, and the full-screen quad geometry that the
// device-domain materials (blit, splat overlay) are drawn on.
#pragma once

namespace filament {
class Engine;
class Material;
class VertexBuffer;
class IndexBuffer;
}  // namespace filament

namespace open3d {
namespace visualization {
namespace rendering {

class FilamentMaterials {
public:
    explicit FilamentMaterials(filament::Engine& engine);
    ~FilamentMaterials();
    FilamentMaterials(const FilamentMaterials&) = delete;
    FilamentMaterials& operator=(const FilamentMaterials&) = delete;

    /// MaterialRecord "defaultUnlit" (parameters baseColor: float4, pointSize: float).
    filament::Material* DefaultUnlit() const { return default_unlit_; }
    /// MaterialRecord "defaultLit" (baseColor: float4, lightDirection: float3, ambient:
    /// float; the vertex normal in CUSTOM0).
    filament::Material* DefaultLit() const { return default_lit_; }
    /// Copies a same-size texture to the screen texel for texel (parameter image).
    filament::Material* SceneBlit() const { return scene_blit_; }
    /// Blends a premultiplied RGBA16F image "over", flipping y (parameter image).
    filament::Material* SplatOverlay() const { return splat_overlay_; }

    /// Two triangles covering clip space, for device-domain materials.
    filament::VertexBuffer* QuadVertices() const { return quad_vertices_; }
    filament::IndexBuffer* QuadIndices() const { return quad_indices_; }

private:
    filament::Engine& engine_;
    filament::Material* default_unlit_ = nullptr;
    filament::Material* default_lit_ = nullptr;
    filament::Material* scene_blit_ = nullptr;
    filament::Material* splat_overlay_ = nullptr;
    filament::VertexBuffer* quad_vertices_ = nullptr;
    filament::IndexBuffer* quad_indices_ = nullptr;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
