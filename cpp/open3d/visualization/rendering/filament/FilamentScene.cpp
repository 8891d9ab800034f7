#include "open3d/visualization/rendering/filament/FilamentScene.h"

#include <filament/Box.h>
#include <filament/Engine.h>
#include <filament/IndexBuffer.h>
#include <filament/Material.h>
#include <filament/MaterialInstance.h>
#include <filament/RenderableManager.h>
#include <filament/Scene.h>
#include <filament/VertexBuffer.h>
#include <math/vec3.h>
#include <math/vec4.h>
#include <utils/EntityManager.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/visualization/rendering/filament/FilamentMaterials.h"

namespace open3d {
namespace visualization {
namespace rendering {

namespace {

// Filament uploads buffers asynchronously: hand it a heap copy it frees when done.
template <typename T>
filament::backend::BufferDescriptor OwnedDescriptor(std::vector<T> data) {
    const size_t bytes = data.size() * sizeof(T);
    void* copy = std::malloc(bytes);
    std::memcpy(copy, data.data(), bytes);
    return filament::backend::BufferDescriptor(
        copy, bytes, [](void* buffer, size_t, void*) { std::free(buffer); });
}

// The shaders a geometry kind can be drawn with.
void CheckShader(const std::string& name, const std::string& shader, bool mesh) {
    const bool known = shader == kShaderDefaultUnlit || shader == kShaderDefaultLit ||
                       shader == kShaderGaussianSplat;
    if (!known) {
        core::ThrowError("'{}': unknown shader '{}' (use {}, {} or {})", name, shader,
                         kShaderDefaultUnlit, kShaderDefaultLit, kShaderGaussianSplat);
    }
    if (mesh && shader == kShaderGaussianSplat) {
        core::ThrowError("'{}': the shader gaussianSplat draws point clouds, not meshes", name);
    }
}

// Float32 [N, 3] in [0, 1] or UInt8 [N, 3] colours as RGBA floats; white without colours.
std::vector<float> VertexColors(const core::Tensor* colors, int64_t n) {
    std::vector<float> rgba(4 * n, 1.0f);
    if (colors == nullptr) return rgba;
    if (colors->NumDims() != 2 || colors->GetShape(0) != n || colors->GetShape(1) != 3) {
        core::ThrowError("colours must be [{}, 3]", n);
    }
    for (int64_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) {
            rgba[4 * i + k] = colors->GetDtype() == core::Dtype::UInt8
                                  ? colors->Data<uint8_t>()[3 * i + k] / 255.0f
                                  : colors->Data<float>()[3 * i + k];
        }
    }
    return rgba;
}

}  // namespace

FilamentScene::FilamentScene(filament::Engine& engine, const FilamentMaterials& materials,
                             std::unique_ptr<GaussianSplatBackend> backend)
    : engine_(engine), materials_(materials), splats_(std::move(backend)) {
    scene_ = engine_.createScene();
}

FilamentScene::~FilamentScene() {
    ClearGeometry();
    engine_.destroy(scene_);
}

FilamentScene::Mesh FilamentScene::BuildMesh(const t::geometry::TriangleMesh& input,
                                             const MaterialRecord& material) {
    input.Validate();
    if (input.IsEmpty() || !input.HasTriangleIndices()) {
        core::ThrowError("FilamentScene: a mesh needs vertices and triangles");
    }
    const bool lit = material.shader == kShaderDefaultLit;
    t::geometry::TriangleMesh mesh = input;
    if (lit && !mesh.HasVertexNormals()) mesh.ComputeVertexNormals();
    const int64_t n = mesh.NumVertices();
    const float* p = mesh.GetVertexPositions().Data<float>();
    std::vector<float> positions(p, p + 3 * n);
    std::vector<float> colors =
        VertexColors(mesh.HasVertexColors() ? &mesh.GetVertexColors() : nullptr, n);
    std::vector<float> normals;
    if (lit) {
        const float* nrm = mesh.GetVertexNormals().Data<float>();
        normals.assign(nrm, nrm + 3 * n);
    }
    std::vector<uint32_t> indices;
    indices.reserve(3 * mesh.NumTriangles());
    for (const Eigen::Vector3i& t : mesh.GetTriangleIndices()) {
        for (int k = 0; k < 3; ++k) indices.push_back(static_cast<uint32_t>(t[k]));
    }

    using filament::VertexBuffer;
    Mesh out;
    out.look = material;
    out.min_bound = mesh.GetMinBound();
    out.max_bound = mesh.GetMaxBound();
    VertexBuffer::Builder builder;
    builder.vertexCount(static_cast<uint32_t>(n))
        .bufferCount(lit ? 3 : 2)
        .attribute(filament::VertexAttribute::POSITION, 0, VertexBuffer::AttributeType::FLOAT3, 0,
                   12)
        .attribute(filament::VertexAttribute::COLOR, 1, VertexBuffer::AttributeType::FLOAT4, 0, 16);
    if (lit) {
        builder.attribute(filament::VertexAttribute::CUSTOM0, 2,
                          VertexBuffer::AttributeType::FLOAT3, 0, 12);
    }
    out.vertices = builder.build(engine_);
    out.vertices->setBufferAt(engine_, 0, OwnedDescriptor(std::move(positions)));
    out.vertices->setBufferAt(engine_, 1, OwnedDescriptor(std::move(colors)));
    if (lit) out.vertices->setBufferAt(engine_, 2, OwnedDescriptor(std::move(normals)));
    out.indices = filament::IndexBuffer::Builder()
                      .indexCount(static_cast<uint32_t>(indices.size()))
                      .bufferType(filament::IndexBuffer::IndexType::UINT)
                      .build(engine_);
    const size_t num_indices = indices.size();
    out.indices->setBuffer(engine_, OwnedDescriptor(std::move(indices)));
    Finish(out, static_cast<int>(filament::RenderableManager::PrimitiveType::TRIANGLES),
           num_indices);
    return out;
}

FilamentScene::Mesh FilamentScene::BuildPoints(const t::geometry::PointCloud& cloud,
                                               const MaterialRecord& material) {
    if (!cloud.HasPointAttr("positions")) {
        core::ThrowError("FilamentScene: a point cloud needs positions");
    }
    const core::Tensor& positions_tensor = cloud.GetPointPositions();
    const int64_t n = positions_tensor.GetShape(0);
    if (n == 0 || positions_tensor.NumDims() != 2 || positions_tensor.GetShape(1) != 3 ||
        positions_tensor.GetDtype() != core::Dtype::Float32) {
        core::ThrowError("FilamentScene: point positions must be Float32 [N > 0, 3]");
    }
    const float* p = positions_tensor.Data<float>();
    std::vector<float> positions(p, p + 3 * n);
    std::vector<float> colors =
        VertexColors(cloud.HasPointAttr("colors") ? &cloud.GetPointAttr("colors") : nullptr, n);
    std::vector<uint32_t> indices(n);
    for (int64_t i = 0; i < n; ++i) indices[i] = static_cast<uint32_t>(i);

    using filament::VertexBuffer;
    Mesh out;
    out.points = true;
    out.look = material;
    const Eigen::Map<const Eigen::Matrix<float, 3, Eigen::Dynamic>> points(p, 3, n);
    out.min_bound = points.rowwise().minCoeff().cast<double>();
    out.max_bound = points.rowwise().maxCoeff().cast<double>();
    out.vertices = VertexBuffer::Builder()
                       .vertexCount(static_cast<uint32_t>(n))
                       .bufferCount(2)
                       .attribute(filament::VertexAttribute::POSITION, 0,
                                  VertexBuffer::AttributeType::FLOAT3, 0, 12)
                       .attribute(filament::VertexAttribute::COLOR, 1,
                                  VertexBuffer::AttributeType::FLOAT4, 0, 16)
                       .build(engine_);
    out.vertices->setBufferAt(engine_, 0, OwnedDescriptor(std::move(positions)));
    out.vertices->setBufferAt(engine_, 1, OwnedDescriptor(std::move(colors)));
    out.indices = filament::IndexBuffer::Builder()
                      .indexCount(static_cast<uint32_t>(n))
                      .bufferType(filament::IndexBuffer::IndexType::UINT)
                      .build(engine_);
    out.indices->setBuffer(engine_, OwnedDescriptor(std::move(indices)));
    Finish(out, static_cast<int>(filament::RenderableManager::PrimitiveType::POINTS), size_t(n));
    return out;
}

void FilamentScene::Finish(Mesh& out, int primitive, size_t num_indices) {
    const MaterialRecord& look = out.look;
    // Points are drawn unlit: they carry no normals.
    const bool lit = !out.points && look.shader == kShaderDefaultLit;
    out.material = (lit ? materials_.DefaultLit() : materials_.DefaultUnlit())->createInstance();
    const Eigen::Vector4f& rgba = look.base_color;
    out.material->setParameter("baseColor",
                               filament::math::float4(rgba[0], rgba[1], rgba[2], rgba[3]));
    if (lit) {
        out.material->setParameter(
            "lightDirection",
            filament::math::float3(light_direction_[0], light_direction_[1], light_direction_[2]));
        out.material->setParameter("ambient", ambient_);
    } else {
        out.material->setParameter("pointSize", look.point_size);
    }
    const Eigen::Vector3d center = 0.5 * (out.min_bound + out.max_bound);
    // A flat extent (one point, a plane) still needs a box Filament does not cull.
    const Eigen::Vector3d half =
        (0.5 * (out.max_bound - out.min_bound)).cwiseMax(Eigen::Vector3d::Constant(1e-3));
    utils::Entity entity = utils::EntityManager::get().create();
    filament::RenderableManager::Builder(1)
        .boundingBox({{float(center.x()), float(center.y()), float(center.z())},
                      {float(half.x()), float(half.y()), float(half.z())}})
        .material(0, out.material)
        .geometry(0, static_cast<filament::RenderableManager::PrimitiveType>(primitive),
                  out.vertices, out.indices, 0, num_indices)
        .castShadows(false)
        .receiveShadows(false)
        .build(engine_, entity);
    out.entity = entity.getId();
}

void FilamentScene::DestroyMesh(Mesh& mesh) {
    const utils::Entity entity = utils::Entity::import(mesh.entity);
    scene_->remove(entity);
    engine_.destroy(entity);
    utils::EntityManager::get().destroy(entity);
    engine_.destroy(mesh.material);
    engine_.destroy(mesh.vertices);
    engine_.destroy(mesh.indices);
}

void FilamentScene::ReplaceMesh(Mesh& old, Mesh built) {
    built.visible = old.visible;
    DestroyMesh(old);
    if (built.visible) scene_->addEntity(utils::Entity::import(built.entity));
    old = built;
}

void FilamentScene::AddMesh(const std::string& name, Mesh built) {
    scene_->addEntity(utils::Entity::import(built.entity));
    meshes_.emplace(name, built);
}

void FilamentScene::AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud) {
    MaterialRecord material;
    material.shader = cloud.IsGaussianSplat() ? kShaderGaussianSplat : kShaderDefaultUnlit;
    AddGeometry(name, cloud, material);
}

void FilamentScene::AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud,
                                const MaterialRecord& material) {
    if (HasGeometry(name)) core::ThrowError("FilamentScene: a geometry named '{}' exists", name);
    CheckShader(name, material.shader, false);
    if (material.shader == kShaderGaussianSplat) {
        if (!cloud.IsGaussianSplat()) {
            core::ThrowError(
                "FilamentScene: '{}' has the shader gaussianSplat but lacks Gaussian "
                "attributes (positions, rot, scale, opacity, f_dc); draw it with "
                "defaultUnlit to show its points",
                name);
        }
        splats_.AddCloud(name, cloud);
        cloud_materials_[name] = material;
        return;
    }
    AddMesh(name, BuildPoints(cloud, material));
}

void FilamentScene::AddGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh,
                                const MaterialRecord& material) {
    if (HasGeometry(name)) core::ThrowError("FilamentScene: a geometry named '{}' exists", name);
    CheckShader(name, material.shader, true);
    AddMesh(name, BuildMesh(mesh, material));
}

void FilamentScene::UpdateGeometry(const std::string& name, const t::geometry::PointCloud& cloud) {
    if (splats_.HasCloud(name)) {
        splats_.UpdateCloud(name, cloud);
        return;
    }
    auto it = meshes_.find(name);
    if (it == meshes_.end() || !it->second.points) {
        core::ThrowError("FilamentScene: no point cloud named '{}'", name);
    }
    ReplaceMesh(it->second, BuildPoints(cloud, it->second.look));
}

void FilamentScene::UpdateGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh) {
    auto it = meshes_.find(name);
    if (it == meshes_.end() || it->second.points) {
        core::ThrowError("FilamentScene: no mesh named '{}'", name);
    }
    // The material carries over to the new mesh.
    ReplaceMesh(it->second, BuildMesh(mesh, it->second.look));
}

bool FilamentScene::RemoveGeometry(const std::string& name) {
    if (auto it = meshes_.find(name); it != meshes_.end()) {
        DestroyMesh(it->second);
        meshes_.erase(it);
        return true;
    }
    cloud_materials_.erase(name);
    return splats_.RemoveCloud(name);
}

void FilamentScene::ShowGeometry(const std::string& name, bool show) {
    if (auto it = meshes_.find(name); it != meshes_.end()) {
        if (it->second.visible == show) return;
        const utils::Entity entity = utils::Entity::import(it->second.entity);
        if (show) {
            scene_->addEntity(entity);
        } else {
            scene_->remove(entity);
        }
        it->second.visible = show;
        return;
    }
    if (!splats_.HasCloud(name)) core::ThrowError("FilamentScene: no geometry named '{}'", name);
    splats_.ShowCloud(name, show);
}

bool FilamentScene::HasGeometry(const std::string& name) const {
    return meshes_.count(name) > 0 || splats_.HasCloud(name);
}

bool FilamentScene::IsGeometryVisible(const std::string& name) const {
    if (auto it = meshes_.find(name); it != meshes_.end()) return it->second.visible;
    if (splats_.HasCloud(name)) return splats_.IsCloudVisible(name);
    core::ThrowError("FilamentScene: no geometry named '{}'", name);
}

const MaterialRecord& FilamentScene::GetMaterial(const std::string& name) const {
    if (auto it = meshes_.find(name); it != meshes_.end()) return it->second.look;
    if (auto it = cloud_materials_.find(name); it != cloud_materials_.end()) return it->second;
    core::ThrowError("FilamentScene: no geometry named '{}'", name);
}

std::vector<std::string> FilamentScene::GetGeometryNames() const {
    std::vector<std::string> names = splats_.GetCloudNames();
    for (const auto& [name, mesh] : meshes_) names.push_back(name);
    std::sort(names.begin(), names.end());
    return names;
}

void FilamentScene::ClearGeometry() {
    for (auto& [name, mesh] : meshes_) DestroyMesh(mesh);
    meshes_.clear();
    splats_.Clear();
    cloud_materials_.clear();
}

void FilamentScene::SetLighting(const Eigen::Vector3f& direction, float ambient, LightFrame frame) {
    if (!(direction.norm() > 0.0f) || !(ambient >= 0.0f && ambient <= 1.0f)) {
        core::ThrowError("SetLighting: the direction must be non-zero and ambient in [0, 1]");
    }
    light_direction_ = direction;
    light_frame_ = frame;
    ambient_ = ambient;
    if (frame == LightFrame::kWorld) world_light_ = direction;
    for (auto& [name, mesh] : meshes_) {
        if (mesh.points || mesh.look.shader != kShaderDefaultLit) continue;
        mesh.material->setParameter(
            "lightDirection",
            filament::math::float3(world_light_[0], world_light_[1], world_light_[2]));
        mesh.material->setParameter("ambient", ambient);
    }
}

void FilamentScene::PrepareLighting(const camera::PinholeCamera& camera) {
    if (light_frame_ != LightFrame::kCamera) return;
    // Camera to world: the transpose of the world-to-camera rotation.
    const Eigen::Vector3f world =
        (camera.GetRotation().transpose() * light_direction_.cast<double>()).cast<float>();
    if (world == world_light_) return;
    world_light_ = world;
    for (auto& [name, mesh] : meshes_) {
        if (mesh.points || mesh.look.shader != kShaderDefaultLit) continue;
        mesh.material->setParameter("lightDirection",
                                    filament::math::float3(world[0], world[1], world[2]));
    }
}

bool FilamentScene::HasNonGaussianVisibleGeometry() const {
    for (const auto& [name, mesh] : meshes_) {
        if (mesh.visible) return true;
    }
    return false;
}

bool FilamentScene::HasVisibleGaussianSplats() const { return splats_.HasVisibleSplats(); }

bool FilamentScene::GetBounds(Eigen::Vector3d& min_bound, Eigen::Vector3d& max_bound) const {
    bool any = splats_.GetBounds(min_bound, max_bound);
    for (const auto& [name, mesh] : meshes_) {
        if (!mesh.visible) continue;
        min_bound = any ? min_bound.cwiseMin(mesh.min_bound) : mesh.min_bound;
        max_bound = any ? max_bound.cwiseMax(mesh.max_bound) : mesh.max_bound;
        any = true;
    }
    return any;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
