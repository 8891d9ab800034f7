#include "open3d/visualization/rendering/filament/FilamentMaterials.h"

#include <filament/Engine.h>
#include <filament/IndexBuffer.h>
#include <filament/Material.h>
#include <filament/VertexBuffer.h>

#include <cstdint>
#include <span>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/filament/EmbeddedMaterials.h"

namespace open3d {
namespace visualization {
namespace rendering {

namespace {

filament::Material* LoadMaterial(filament::Engine& engine, std::span<const uint8_t> package,
                                 const char* name) {
    filament::Material* material =
        filament::Material::Builder().package(package.data(), package.size()).build(engine);
    if (material == nullptr) core::ThrowError("Filament: cannot load the material '{}'", name);
    return material;
}

// Clip-space corners; static storage because Filament reads them asynchronously.
const float kQuadCorners[] = {-1.f, -1.f, 1.f, -1.f, 1.f, 1.f, -1.f, 1.f};
const uint16_t kQuadTriangles[] = {0, 1, 2, 0, 2, 3};

}  // namespace

FilamentMaterials::FilamentMaterials(filament::Engine& engine) : engine_(engine) {
    default_unlit_ = LoadMaterial(engine, materials::kDefaultUnlit, "default_unlit");
    default_lit_ = LoadMaterial(engine, materials::kDefaultLit, "default_lit");
    scene_blit_ = LoadMaterial(engine, materials::kSceneBlit, "scene_blit");
    splat_overlay_ = LoadMaterial(engine, materials::kSplatOverlay, "splat_overlay");
    using filament::VertexBuffer;
    quad_vertices_ = VertexBuffer::Builder()
                         .vertexCount(4)
                         .bufferCount(1)
                         .attribute(filament::VertexAttribute::POSITION, 0,
                                    VertexBuffer::AttributeType::FLOAT2, 0, 8)
                         .build(engine);
    quad_vertices_->setBufferAt(engine, 0,
                                VertexBuffer::BufferDescriptor(kQuadCorners, sizeof(kQuadCorners)));
    quad_indices_ = filament::IndexBuffer::Builder()
                        .indexCount(6)
                        .bufferType(filament::IndexBuffer::IndexType::USHORT)
                        .build(engine);
    quad_indices_->setBuffer(
        engine, filament::IndexBuffer::BufferDescriptor(kQuadTriangles, sizeof(kQuadTriangles)));
}

FilamentMaterials::~FilamentMaterials() {
    engine_.destroy(quad_vertices_);
    engine_.destroy(quad_indices_);
    engine_.destroy(default_unlit_);
    engine_.destroy(default_lit_);
    engine_.destroy(scene_blit_);
    engine_.destroy(splat_overlay_);
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
