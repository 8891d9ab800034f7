// The two images a splat view shares between the splat backend and Filament (docs/filament.md
// "Zero-copy images"): the composite's premultiplied RGBA16F colour, drawn by the overlay,
// and a D32F scene depth, the mesh view's depth attachment that the composite tests splats
// against. Two ways to share them, chosen when the targets are made:
// - zero-copy: Vulkan memory exported as fds, imported into GL (GL_EXT_memory_object_fd)
//   and into Filament; needs the Vulkan backend, the extensions on both sides and matching
//   device/driver UUIDs;
// - host copy: plain GL textures; the depth is read with glGetTextureImage, the backend
//   composites from host memory (any backend), and the colour is uploaded back.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "open3d/t/geometry/Image.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"

namespace filament {
class Texture;
}  // namespace filament

namespace open3d {
namespace visualization {
namespace rendering {

class FilamentEngine;
namespace vulkan {
class InteropTargets;
}  // namespace vulkan

/// How the splat images reach Filament.
enum class SplatSharing {
    kAuto,      ///< zero-copy where possible, else host copy (the reason is logged once)
    kZeroCopy,  ///< zero-copy or an error
    kHostCopy,  ///< always host copy (for tests and drivers that misbehave)
};

/// Parses "auto", "zero-copy" or "host-copy"; throws core::Open3DError otherwise.
SplatSharing ParseSplatSharing(const std::string& text);

/// Why `backend` cannot share images zero-copy with the GL context current on this thread,
/// or an empty string when it can.
std::string ZeroCopyUnavailableReason(const FilamentEngine& engine,
                                      const GaussianSplatBackend& backend);

struct SplatCompositeRequest {
    /// A mesh is visible: test splats against the scene depth (else no depth is read).
    bool use_scene_depth = false;
    /// Near plane of the mesh view's projection: z_view = scene_near / d.
    float scene_near = 0.1f;
    bool read_color = false;  ///< fill SplatFrame::color
    /// Fill SplatFrame::blended on the GPU (zero-copy targets only): the splats over the
    /// mesh view's colour, which Filament drew into GetMeshColorTexture().
    bool blend_over_mesh = false;
    bool read_depth = false;  ///< fill SplatFrame::linear_depth / normalized_depth
    float depth_near = 0.2f;  ///< normalisation of normalized_depth
    float depth_far = 100.0f;
    /// The frame is presented (a swap chain's compose view samples the colour) and reads
    /// nothing back: with HasGpuHandover() Vulkan signals "splats drawn" and the host does
    /// not wait for the composite; WaitSplatsDrawn must then come before the compose view.
    bool presented = false;
};

struct SplatFrame {
    t::geometry::Image color;             ///< Float32 [H, W, 4] premultiplied, top row first
    t::geometry::Image blended;           ///< UInt8 [H, W, 4] splats over mesh, top row first
    t::geometry::Image linear_depth;      ///< Float32 [H, W, 1] merged view z, 0 = nothing
    t::geometry::Image normalized_depth;  ///< UInt16 [H, W, 1], 65535 = nothing
    RenderStats stats;
};

class SplatTargets {
public:
    /// Images of width x height for `backend`. Throws core::Open3DError when `sharing` is
    /// kZeroCopy and zero-copy is unavailable (with the reason).
    SplatTargets(FilamentEngine& engine, GaussianSplatBackend& backend, uint32_t width,
                 uint32_t height, SplatSharing sharing);
    /// Destroys the Filament textures, then the GL textures and memory, then the Vulkan
    /// images. Filament must no longer use them (the caller detached them and flushed).
    ~SplatTargets();
    SplatTargets(const SplatTargets&) = delete;
    SplatTargets& operator=(const SplatTargets&) = delete;

    uint32_t GetWidth() const { return width_; }
    uint32_t GetHeight() const { return height_; }
    bool IsZeroCopy() const { return interop_ != nullptr; }

    /// RGBA16F, sampled by the overlay material (row 0 = the image's top row).
    filament::Texture* GetColorTexture() const { return color_texture_; }
    /// DEPTH32F, the mesh view's depth attachment (Filament writes reversed-Z).
    filament::Texture* GetDepthTexture() const { return depth_texture_; }
    /// RGBA8, for the mesh view's colour attachment (zero-copy only, else null): Vulkan reads
    /// it for the blend over the mesh colour.
    filament::Texture* GetMeshColorTexture() const { return mesh_color_texture_; }
    /// Its GL texture name (0 without zero-copy), for tests that read it from GL.
    uint32_t GetMeshColorGlName() const { return gl_mesh_color_; }

    /// GPU-side hand-over between GL and Vulkan: whether GL signals a semaphore after the mesh
    /// view that the composite waits for, and a presented frame's composite signals one GL
    /// waits for before its compose view (zero-copy where Vulkan exports and GL imports
    /// semaphores, unless OPEN3D_GL_VK_SEMAPHORES=0), instead of the host waiting.
    bool HasGpuHandover() const { return gl_mesh_drawn_ != 0; }
    /// After Filament's mesh view was issued: GL signals "mesh drawn" on Filament's thread
    /// after it, and this returns once that signal is flushed to the GPU (no wait for the GPU
    /// work). The next Composite waits for it on the GPU. False, and nothing is signalled,
    /// without HasGpuHandover(): then wait for Filament on the host (flushAndWait).
    bool SignalMeshDrawn();

    /// Before Filament's compose view samples the colour (EndFrame): GL waits on the GPU, on
    /// Filament's thread, for the composite that signalled "splats drawn" (a presented frame
    /// with HasGpuHandover()). Returns whether a wait was issued (false when none was owed).
    bool WaitSplatsDrawn();

    /// Composite stage of the backend's last geometry stage into the colour image, after Filament
    /// drew the mesh view and either finished (flushAndWait) or SignalMeshDrawn.
    void Composite(GaussianSplatBackend& backend, const SplatCompositeRequest& request,
                   SplatFrame& frame);

    /// The mesh view's depth alone as merged depth (no splat is visible): read from GL.
    void ReadMeshDepth(float scene_near, float depth_near, float depth_far, SplatFrame& frame);

private:
    /// The scene depth as view z ([H, W, 1] Float32, top row first, 0 = nothing drawn).
    t::geometry::Image ReadSceneDepth(float scene_near);
    void CreateZeroCopy(GaussianSplatBackend& backend);
    void CreateHostCopy();
    // Imports the "mesh drawn" semaphore where both sides can; logs the choice once.
    void SetUpGpuHandover(GaussianSplatBackend& backend);
    // Wraps the two GL textures (complete, finished) as Filament textures.
    void ImportIntoFilament();
    void CompositeHostCopy(GaussianSplatBackend& backend, const SplatCompositeRequest& request,
                           SplatFrame& frame);

    FilamentEngine& engine_;
    uint32_t width_ = 0;
    uint32_t height_ = 0;
    std::unique_ptr<vulkan::InteropTargets> interop_;
    uint32_t gl_color_ = 0, gl_depth_ = 0, gl_mesh_color_ = 0;  // GL texture names
    uint32_t gl_memory_[3] = {0, 0, 0};   // GL memory objects (zero-copy only)
    uint32_t gl_mesh_drawn_ = 0;          // GL semaphore (GPU hand-over only)
    bool mesh_drawn_signaled_ = false;    // signalled, not yet waited for by a composite
    bool splats_drawn_handover_ = true;   // OPEN3D_GL_VK_SEMAPHORES is not "mesh"
    uint32_t gl_splats_drawn_ = 0;        // GL semaphore: Vulkan's composite is done
    bool splats_drawn_signaled_ = false;  // signalled by a composite, GL has not waited yet
    filament::Texture* color_texture_ = nullptr;
    filament::Texture* depth_texture_ = nullptr;
    filament::Texture* mesh_color_texture_ = nullptr;  // zero-copy only
};

/// The host-side depth merge (the GPU depth merge's rule, for the host-copy path): per pixel
/// the nearer of the splat expected depth (where 0 < alpha and alpha >= min_alpha, alpha =
/// splats.color channel 3) and the scene view z (> 0), 0 where neither; normalised
/// u = round(65535 * clamp((z - near) / (far - near))), 65535 where nothing is.
/// `splats` (null: none) and `scene_z` ([H, W, 1] Float32 top row first, null: none) may
/// not both be null.
void MergeDepthOnHost(const RenderOutput* splats, const t::geometry::Image* scene_z, float near,
                      float far, float min_alpha, t::geometry::Image& linear,
                      t::geometry::Image& normalized);

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
