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

#include <cstdlib>
#include <cstring>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/filament/FilamentMaterials.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatMerge.h"

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

}  // namespace

FilamentScene::FilamentScene(filament::Engine& engine, const FilamentMaterials& materials,
                             std::unique_ptr<GaussianSplatBackend> backend)
    : engine_(engine), materials_(materials), backend_(std::move(backend)) {
    scene_ = engine_.createScene();
}

FilamentScene::~FilamentScene() {
    ClearGeometry();
    engine_.destroy(scene_);
}

FilamentScene::Mesh FilamentScene::BuildMesh(const t::geometry::TriangleMesh& mesh,
                                             const MeshMaterial& material) {
    mesh.Validate();
    if (mesh.IsEmpty() || !mesh.HasTriangleIndices()) {
        core::ThrowError("FilamentScene: a mesh needs vertices and triangles");
    }
    const int64_t n = mesh.NumVertices();
    const float* p = mesh.GetVertexPositions().Data<float>();
    const float* c = mesh.HasVertexColors() ? mesh.GetVertexColors().Data<float>() : nullptr;
    std::vector<float> positions(p, p + 3 * n);
    std::vector<float> colors(4 * n, 1.0f);
    for (int64_t i = 0; c != nullptr && i < n; ++i) {
        for (int k = 0; k < 3; ++k) colors[4 * i + k] = c[3 * i + k];
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
                      .indexCount(static_cast<uint32_t>(indices.size()))
                      .bufferType(filament::IndexBuffer::IndexType::UINT)
                      .build(engine_);
    const size_t num_indices = indices.size();
    out.indices->setBuffer(engine_, OwnedDescriptor(std::move(indices)));
    out.material = materials_.MeshUnlit()->createInstance();
    const Eigen::Vector4f& rgba = material.base_color;
    out.material->setParameter("baseColor",
                               filament::math::float4(rgba[0], rgba[1], rgba[2], rgba[3]));
    out.material->setParameter("shading", material.shading);

    const Eigen::Vector3d center = 0.5 * (out.min_bound + out.max_bound);
    const Eigen::Vector3d half = 0.5 * (out.max_bound - out.min_bound);
    utils::Entity entity = utils::EntityManager::get().create();
    filament::RenderableManager::Builder(1)
        .boundingBox({{float(center.x()), float(center.y()), float(center.z())},
                      {float(half.x()), float(half.y()), float(half.z())}})
        .material(0, out.material)
        .geometry(0, filament::RenderableManager::PrimitiveType::TRIANGLES, out.vertices,
                  out.indices, 0, num_indices)
        .castShadows(false)
        .receiveShadows(false)
        .build(engine_, entity);
    out.entity = entity.getId();
    return out;
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

void FilamentScene::AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud) {
    if (HasGeometry(name)) core::ThrowError("FilamentScene: a geometry named '{}' exists", name);
    cloud.ValidateGaussianSplat();
    clouds_.emplace(name, Cloud{cloud, 0, true});
    merged_dirty_ = true;
}

void FilamentScene::AddGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh,
                                const MeshMaterial& material) {
    if (HasGeometry(name)) core::ThrowError("FilamentScene: a geometry named '{}' exists", name);
    Mesh built = BuildMesh(mesh, material);
    scene_->addEntity(utils::Entity::import(built.entity));
    meshes_.emplace(name, built);
}

void FilamentScene::UpdateGeometry(const std::string& name, const t::geometry::PointCloud& cloud) {
    auto it = clouds_.find(name);
    if (it == clouds_.end()) core::ThrowError("FilamentScene: no splat cloud named '{}'", name);
    cloud.ValidateGaussianSplat();
    it->second.cloud = cloud;
    merged_dirty_ = true;
}

void FilamentScene::UpdateGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh) {
    auto it = meshes_.find(name);
    if (it == meshes_.end()) core::ThrowError("FilamentScene: no mesh named '{}'", name);
    // The material carries over to the new mesh.
    Mesh built = BuildMesh(mesh, it->second.look);
    built.visible = it->second.visible;
    DestroyMesh(it->second);
    if (built.visible) scene_->addEntity(utils::Entity::import(built.entity));
    it->second = built;
}

bool FilamentScene::RemoveGeometry(const std::string& name) {
    if (auto it = meshes_.find(name); it != meshes_.end()) {
        DestroyMesh(it->second);
        meshes_.erase(it);
        return true;
    }
    if (clouds_.erase(name) > 0) {
        merged_dirty_ = true;
        return true;
    }
    return false;
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
    auto it = clouds_.find(name);
    if (it == clouds_.end()) core::ThrowError("FilamentScene: no geometry named '{}'", name);
    if (it->second.visible == show) return;
    it->second.visible = show;
    // Without a mask in the backend, hidden clouds are left out of the merged scene.
    if (merged_uses_mask_) {
        mask_dirty_ = true;
    } else {
        merged_dirty_ = true;
    }
}

bool FilamentScene::HasGeometry(const std::string& name) const {
    return meshes_.count(name) > 0 || clouds_.count(name) > 0;
}

bool FilamentScene::IsGeometryVisible(const std::string& name) const {
    if (auto it = meshes_.find(name); it != meshes_.end()) return it->second.visible;
    if (auto it = clouds_.find(name); it != clouds_.end()) return it->second.visible;
    core::ThrowError("FilamentScene: no geometry named '{}'", name);
}

std::vector<std::string> FilamentScene::GetGeometryNames() const {
    std::vector<std::string> names;
    for (const auto& [name, mesh] : meshes_) names.push_back(name);
    for (const auto& [name, cloud] : clouds_) names.push_back(name);
    std::sort(names.begin(), names.end());
    return names;
}

void FilamentScene::ClearGeometry() {
    for (auto& [name, mesh] : meshes_) DestroyMesh(mesh);
    meshes_.clear();
    if (!clouds_.empty()) merged_dirty_ = true;
    clouds_.clear();
}

bool FilamentScene::HasNonGaussianVisibleGeometry() const {
    for (const auto& [name, mesh] : meshes_) {
        if (mesh.visible) return true;
    }
    return false;
}

bool FilamentScene::HasVisibleGaussianSplats() const {
    for (const auto& [name, cloud] : clouds_) {
        if (cloud.visible && cloud.cloud.GetPointPositions().GetShape(0) > 0) return true;
    }
    return false;
}

bool FilamentScene::GetBounds(Eigen::Vector3d& min_bound, Eigen::Vector3d& max_bound) const {
    bool any = false;
    const auto grow = [&](const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
        min_bound = any ? min_bound.cwiseMin(lo) : lo;
        max_bound = any ? max_bound.cwiseMax(hi) : hi;
        any = true;
    };
    for (const auto& [name, mesh] : meshes_) {
        if (mesh.visible) grow(mesh.min_bound, mesh.max_bound);
    }
    for (const auto& [name, cloud] : clouds_) {
        const core::Tensor& p = cloud.cloud.GetPointPositions();
        if (!cloud.visible || p.GetShape(0) == 0) continue;
        const Eigen::Map<const Eigen::Matrix<float, 3, Eigen::Dynamic>> points(p.Data<float>(), 3,
                                                                               p.GetShape(0));
        grow(points.rowwise().minCoeff().cast<double>(),
             points.rowwise().maxCoeff().cast<double>());
    }
    return any;
}

std::vector<uint32_t> FilamentScene::VisibilityMask() const {
    int64_t n = 0;
    for (const auto& [name, cloud] : clouds_) n += cloud.cloud.GetPointPositions().GetShape(0);
    std::vector<uint32_t> mask((n + 31) / 32, 0u);
    for (const auto& [name, cloud] : clouds_) {
        if (!cloud.visible) continue;
        SetSplatVisibility(mask, cloud.first,
                           cloud.first + cloud.cloud.GetPointPositions().GetShape(0), true);
    }
    return mask;
}

void FilamentScene::PrepareSplats() {
    if (merged_dirty_) {
        std::vector<const t::geometry::PointCloud*> parts;
        int64_t first = 0;
        for (auto& [name, cloud] : clouds_) {
            cloud.first = first;
            if (!merged_uses_mask_ && !cloud.visible) continue;
            parts.push_back(&cloud.cloud);
            first += cloud.cloud.GetPointPositions().GetShape(0);
        }
        if (parts.empty()) {
            backend_->ReleaseResources();
        } else {
            backend_->SetScene(MergeGaussianSplatClouds(parts));
            ++counters_.merged_rebuilds;
            // A new scene starts all visible: send a mask only when something is hidden.
            mask_dirty_ = false;
            for (const auto& [name, cloud] : clouds_) mask_dirty_ |= !cloud.visible;
            mask_dirty_ &= merged_uses_mask_;
        }
        merged_dirty_ = false;
    }
    if (mask_dirty_) {
        if (backend_->SetVisibilityMask(VisibilityMask())) {
            ++counters_.mask_updates;
        } else {
            // The backend has no mask: from now on hidden clouds are left out instead.
            merged_uses_mask_ = false;
            merged_dirty_ = true;
            mask_dirty_ = false;
            PrepareSplats();
            return;
        }
        mask_dirty_ = false;
    }
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
