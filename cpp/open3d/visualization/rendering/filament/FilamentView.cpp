#include "open3d/visualization/rendering/filament/FilamentView.h"

#include <filament/Camera.h>
#include <filament/Engine.h>
#include <filament/Material.h>
#include <filament/MaterialInstance.h>
#include <filament/RenderTarget.h>
#include <filament/RenderableManager.h>
#include <filament/Scene.h>
#include <filament/Texture.h>
#include <filament/TextureSampler.h>
#include <filament/View.h>
#include <filament/Viewport.h>
#include <utils/EntityManager.h>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/filament/FilamentCamera.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/filament/FilamentMaterials.h"
#include "open3d/visualization/rendering/filament/FilamentScene.h"

namespace open3d {
namespace visualization {
namespace rendering {

namespace {

// Exact colours in and out: no tone mapping, dithering, anti-aliasing, shadows or MSAA.
void MakePlainView(filament::View& view) {
    view.setPostProcessingEnabled(false);
    view.setShadowingEnabled(false);
    view.setSampleCount(1);
    view.setAntiAliasing(filament::View::AntiAliasing::NONE);
    view.setDithering(filament::View::Dithering::NONE);
}

uint32_t MakeQuad(filament::Engine& engine, const FilamentMaterials& materials,
                  filament::MaterialInstance* material, uint8_t priority) {
    utils::Entity entity = utils::EntityManager::get().create();
    filament::RenderableManager::Builder(1)
        .boundingBox({{0, 0, 0}, {1, 1, 1}})
        .material(0, material)
        .geometry(0, filament::RenderableManager::PrimitiveType::TRIANGLES,
                  materials.QuadVertices(), materials.QuadIndices(), 0, 6)
        .culling(false)
        .castShadows(false)
        .receiveShadows(false)
        .priority(priority)  // the blit first, then the overlay over it
        .build(engine, entity);
    return entity.getId();
}

}  // namespace

FilamentView::FilamentView(FilamentEngine& engine, const FilamentMaterials& materials,
                           SplatSharing sharing)
    : engine_(engine), materials_(materials), sharing_(sharing) {
    filament::Engine& e = engine_.GetEngine();
    utils::EntityManager& entities = utils::EntityManager::get();
    mesh_view_ = e.createView();
    mesh_camera_ = e.createCamera(entities.create());
    mesh_view_->setCamera(mesh_camera_);
    MakePlainView(*mesh_view_);

    compose_view_ = e.createView();
    compose_scene_ = e.createScene();
    compose_camera_ = e.createCamera(entities.create());
    compose_view_->setCamera(compose_camera_);
    compose_view_->setScene(compose_scene_);
    MakePlainView(*compose_view_);
    blit_material_ = materials_.SceneBlit()->createInstance();
    overlay_material_ = materials_.SplatOverlay()->createInstance();
    blit_entity_ = MakeQuad(e, materials_, blit_material_, 0);
    overlay_entity_ = MakeQuad(e, materials_, overlay_material_, 7);
    compose_scene_->addEntity(utils::Entity::import(blit_entity_));
}

FilamentView::~FilamentView() {
    ReleaseTargets();
    filament::Engine& e = engine_.GetEngine();
    utils::EntityManager& entities = utils::EntityManager::get();
    for (uint32_t id : {blit_entity_, overlay_entity_}) {
        const utils::Entity entity = utils::Entity::import(id);
        compose_scene_->remove(entity);
        e.destroy(entity);
        entities.destroy(entity);
    }
    e.destroy(blit_material_);
    e.destroy(overlay_material_);
    for (filament::Camera* camera : {mesh_camera_, compose_camera_}) {
        const utils::Entity entity = camera->getEntity();
        e.destroyCameraComponent(entity);
        entities.destroy(entity);
    }
    e.destroy(mesh_view_);
    e.destroy(compose_view_);
    e.destroy(compose_scene_);
}

void FilamentView::SetCamera(const camera::PinholeCamera& camera) {
    camera.Validate();
    if (camera.width != camera_.width || camera.height != camera_.height) ReleaseTargets();
    camera_ = camera;
}

void FilamentView::SetOverlayVisible(bool visible) {
    if (visible == overlay_visible_) return;
    const utils::Entity entity = utils::Entity::import(overlay_entity_);
    if (visible) {
        compose_scene_->addEntity(entity);
    } else {
        compose_scene_->remove(entity);
    }
    overlay_visible_ = visible;
}

void FilamentView::ReleaseTargets() {
    if (!splat_targets_ && mesh_target_ == nullptr) return;
    filament::Engine& e = engine_.GetEngine();
    // Nothing may point at the textures when they go: detach, then destroy.
    mesh_view_->setRenderTarget(nullptr);
    e.destroy(mesh_target_);
    // A zero-copy mesh colour belongs to the splat targets.
    if (!splat_targets_ || mesh_color_ != splat_targets_->GetMeshColorTexture()) {
        e.destroy(mesh_color_);
    }
    mesh_target_ = nullptr;
    mesh_color_ = nullptr;
    splat_targets_.reset();  // flushes the engine before freeing the GL and Vulkan images
    targets_backend_ = nullptr;
}

void FilamentView::PrepareTargets(FilamentScene& scene) {
    if (camera_.width <= 0) core::ThrowError("FilamentView: SetCamera before drawing");
    mesh_view_->setScene(scene.GetFilamentScene());
    if (targets_backend_ != &scene.GetBackend()) ReleaseTargets();
    const uint32_t w = static_cast<uint32_t>(camera_.width);
    const uint32_t h = static_cast<uint32_t>(camera_.height);
    filament::Engine& e = engine_.GetEngine();
    if (!splat_targets_) {
        splat_targets_ =
            std::make_unique<SplatTargets>(engine_, scene.GetBackend(), w, h, sharing_);
        targets_backend_ = &scene.GetBackend();
        // Zero-copy: Filament draws the mesh colour into Vulkan memory, which the blend over
        // it reads (FilamentRenderer::Draw, offscreen).
        mesh_color_ = splat_targets_->GetMeshColorTexture();
        if (mesh_color_ == nullptr) {
            mesh_color_ = filament::Texture::Builder()
                              .width(w)
                              .height(h)
                              .levels(1)
                              .sampler(filament::Texture::Sampler::SAMPLER_2D)
                              .format(filament::Texture::InternalFormat::RGBA8)
                              .usage(filament::Texture::Usage::COLOR_ATTACHMENT |
                                     filament::Texture::Usage::SAMPLEABLE)
                              .build(e);
        }
        mesh_target_ = filament::RenderTarget::Builder()
                           .texture(filament::RenderTarget::AttachmentPoint::COLOR, mesh_color_)
                           .texture(filament::RenderTarget::AttachmentPoint::DEPTH,
                                    splat_targets_->GetDepthTexture())
                           .build(e);
        mesh_view_->setRenderTarget(mesh_target_);
        const filament::TextureSampler nearest(filament::TextureSampler::MinFilter::NEAREST,
                                               filament::TextureSampler::MagFilter::NEAREST);
        blit_material_->setParameter("image", mesh_color_, nearest);
        overlay_material_->setParameter("image", splat_targets_->GetColorTexture(), nearest);
        ++target_builds_;
    }
    mesh_view_->setViewport({0, 0, w, h});
    compose_view_->setViewport({0, 0, static_cast<uint32_t>(GetPresentWidth()),
                                static_cast<uint32_t>(GetPresentHeight())});
    SetFilamentCamera(*mesh_camera_, camera_, mesh_near_);
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
