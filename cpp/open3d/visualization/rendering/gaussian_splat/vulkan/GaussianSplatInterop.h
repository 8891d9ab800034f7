// Sharing the Vulkan backend's frame images with an OpenGL renderer (Filament) without
// copies (docs/filament.md "Zero-copy images"): the splat colour (RGBA16F, written by the
// composite), the scene depth (D32_SFLOAT, written by Filament, sampled by the composite)
// and the mesh colour (RGBA8, written by Filament, read by the blend over it) live in
// Vulkan memory exported as POSIX file descriptors, which GL imports
// with GL_EXT_memory_object_fd. This header has no Vulkan types so the Filament layer can
// use it (docs/DESIGN.md "Layers"). GL's mesh view reaches the composite through a semaphore
// GL signals where both sides can export and import one (NVIDIA), else through a host wait
// (lavapipe has no semaphore export, llvmpipe no GL_EXT_semaphore); the composite's results
// reach GL through the host's fence wait.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "open3d/t/geometry/Image.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

/// What the device of a backend can share.
struct InteropSupport {
    /// The backend is the Vulkan backend and its device has VK_KHR_external_memory_fd.
    bool external_memory_fd = false;
    /// ... and VK_KHR_external_semaphore_fd: GL can signal a semaphore that the composite
    /// waits for (InteropTargets::ExportMeshDrawnSemaphore).
    bool external_semaphore_fd = false;
    /// VkPhysicalDeviceIDProperties: GL must report the same UUIDs
    /// (GL_DEVICE_UUID_EXT / GL_DRIVER_UUID_EXT) before it may import the memory.
    std::array<uint8_t, 16> device_uuid{};
    std::array<uint8_t, 16> driver_uuid{};
};

/// Support of `backend`: all false / zero when it is not the Vulkan backend.
InteropSupport QueryInteropSupport(const GaussianSplatBackend& backend);

/// One exported image allocation, for glImportMemoryFdEXT + glTextureStorageMem2DEXT.
struct ExportedImageMemory {
    /// A new descriptor per export. The caller owns it: a successful GL import takes
    /// ownership; otherwise the caller closes it.
    int fd = -1;
    /// Size of the allocation (glImportMemoryFdEXT's size argument).
    uint64_t size = 0;
    /// Always a dedicated allocation: set GL_DEDICATED_MEMORY_OBJECT_EXT before importing.
    bool dedicated = true;
};

struct InteropCompositeRequest;
struct InteropFrame;

/// The images of one view size, made on the backend's device with exportable memory
/// (OPAQUE_FD, dedicated allocations, optimal tiling):
/// - colour: RGBA16F, premultiplied splat colour (rgb = C, a = 1 - T, no background),
///   row 0 = the top image row (GL, whose row 0 is the bottom, must flip y);
/// - depth: D32_SFLOAT, Filament's depth attachment: reversed-Z d = near / z_view, 0 where
///   nothing was drawn, row 0 = GL's bottom row;
/// - mesh colour: RGBA8 unorm, Filament's colour attachment, row 0 = GL's bottom row.
/// All stay in VK_IMAGE_LAYOUT_GENERAL and are owned by the external queue family between
/// composites. Destroy them only after GL/Filament stopped using the imported textures, and
/// before the backend (whose device they live on).
class InteropTargets {
public:
    /// Throws core::Open3DError when `backend` is not the Vulkan backend, its device cannot
    /// export memory, or a size is 0.
    InteropTargets(GaussianSplatBackend& backend, uint32_t width, uint32_t height);
    ~InteropTargets();
    InteropTargets(const InteropTargets&) = delete;
    InteropTargets& operator=(const InteropTargets&) = delete;

    uint32_t GetWidth() const;
    uint32_t GetHeight() const;

    ExportedImageMemory ExportColor();
    ExportedImageMemory ExportDepth();
    /// RGBA8 unorm: the mesh view's colour attachment (row 0 = GL's bottom row), read by the
    /// blend over it (InteropCompositeRequest::blend_over_mesh).
    ExportedImageMemory ExportMeshColor();
    /// A descriptor (OPAQUE_FD, the caller owns it as above) of the binary semaphore "GL drew
    /// the mesh view": GL imports it (GL_EXT_semaphore_fd) and signals it after its draw, with
    /// the depth and mesh colour in GENERAL layout; a composite with
    /// InteropCompositeRequest::wait_mesh_drawn waits for it on the GPU instead of the host
    /// waiting for GL. Made on the first call; every call exports the same semaphore.
    /// Throws core::Open3DError when the device cannot export semaphores.
    int ExportMeshDrawnSemaphore();
    /// A descriptor of the binary semaphore "Vulkan composited the splats": GL imports it and
    /// waits for it (glWaitSemaphoreEXT, colour and depth in GENERAL layout) before it samples
    /// the colour or draws into the depth again. A composite with
    /// InteropCompositeRequest::signal_splats_drawn signals it and, when it reads nothing
    /// back, is not waited for on the host. Made on the first call; same semaphore each call.
    /// Throws core::Open3DError when the device cannot export semaphores.
    int ExportSplatsDrawnSemaphore();

    /// Writes the depth image from the host: `reversed_z` holds width * height floats in GL
    /// row order (bottom row first), stored as given. For tests and for drivers where GL
    /// cannot import. Acquires and releases the image itself and waits for the copy.
    void UploadDepth(const float* reversed_z);

    struct Impl;

private:
    friend void RenderCompositeToInterop(GaussianSplatBackend& backend, InteropTargets& targets,
                                         const InteropCompositeRequest& request,
                                         InteropFrame& frame);
    std::unique_ptr<Impl> impl_;
};

struct InteropCompositeRequest {
    /// Test each splat against the shared depth (some mesh is visible). When false the
    /// pipeline variant without scene depth runs and reads no depth.
    bool use_scene_depth = false;
    /// Near plane of the projection that wrote the depth: z_view = scene_near / d.
    float scene_near = 0.1f;
    /// The submission waits for the "mesh drawn" semaphore (ExportMeshDrawnSemaphore), which
    /// GL signalled once since the last composite that waited for it; without it the caller
    /// must have waited for GL on the host.
    bool wait_mesh_drawn = false;
    /// The submission signals the "splats drawn" semaphore (ExportSplatsDrawnSemaphore), for
    /// which GL must wait once before the next composite signals it again. Without
    /// read_color, blend_over_mesh and read_depth the host then does not wait for the frame.
    bool signal_splats_drawn = false;
    /// Copy the splat colour to InteropFrame::color (offscreen rendering).
    bool read_color = false;
    /// Blend the splat colour over the mesh colour image on the GPU into InteropFrame::blended
    /// (offscreen rendering with an 8-bit picture: no float readback, no host blend).
    bool blend_over_mesh = false;
    /// Merge the splat depth (expected depth where 1 - T >= 0.5) with the scene depth on
    /// the GPU and read both merged images back (RenderToDepthImage).
    bool read_depth = false;
    /// Normalisation of InteropFrame::normalized_depth: 65535 * (z - near) / (far - near).
    float depth_near = 0.2f;
    float depth_far = 100.0f;
};

/// What a composite read back; the images not requested come back empty.
struct InteropFrame {
    /// Float32 [H, W, 4], premultiplied rgb and a = 1 - T, top row first (read_color).
    t::geometry::Image color;
    /// UInt8 [H, W, 4]: round(255 * (s + (1 - s_a) * m)), top row first (blend_over_mesh).
    t::geometry::Image blended;
    /// Float32 [H, W, 1] merged view z, 0 where neither splat nor mesh is (read_depth).
    t::geometry::Image linear_depth;
    /// UInt16 [H, W, 1] merged depth normalised, 65535 where nothing is (read_depth).
    t::geometry::Image normalized_depth;
    /// As RenderCompositeStage reports it (counts, flags, GPU times, geometry_reused).
    RenderStats stats;
};

/// Composite stage of `backend`'s last RenderGeometryStage into `targets`, whose size must equal
/// that camera's. Acquires both images from the external queue family and releases them
/// back in the same command buffer, waits for the fence, then fills `frame`. Entry-buffer
/// growth and empty-frame skips behave as in RenderCompositeStage. Throws core::Open3DError
/// on a size mismatch, a non-Vulkan backend, targets of another backend, when no geometry
/// stage ran, or for a request with scene_near <= 0 (use_scene_depth) or depth_far <=
/// depth_near (read_depth).
void RenderCompositeToInterop(GaussianSplatBackend& backend, InteropTargets& targets,
                              const InteropCompositeRequest& request, InteropFrame& frame);

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
