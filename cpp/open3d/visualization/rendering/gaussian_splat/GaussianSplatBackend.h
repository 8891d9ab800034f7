// The backend interface at stage granularity (docs/DESIGN.md "Code rules"): a backend holds a
// scene, runs the geometry stage (RenderGeometryStage: project + per-tile entries + depth sort) for
// a view, then the composite stage (RenderCompositeStage: per-tile front-to-back blending).
// Backends are made by name ("cpu", "placeholder"; "vulkan" is registered by its layer).
#pragma once

#include <Eigen/Core>

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/Image.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/visualization/rendering/gaussian_splat/BatchHostMemory.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

namespace open3d {
namespace visualization {
namespace rendering {

struct SplatStreamStep;

/// Images of one frame, all camera.height x camera.width.
struct RenderOutput {
    /// Float32 [H, W, 4]: rgb = C + T * background, a = 1 - T (premultiplied when the
    /// background is black).
    t::geometry::Image color;
    /// Float32 [H, W, 1]: sum(alpha_i T_i z_i) / (1 - T), view-space z; 0 where no splat
    /// contributes. Empty unless CompositeInputs::expected_depth.
    t::geometry::Image depth_expected;
    /// Float32 [H, W, 1]: view-space z of the first blended splat after which 1 - T >= 0.5;
    /// 0 where the accumulated alpha never reaches one half. Empty unless
    /// CompositeInputs::median_depth.
    t::geometry::Image depth_median;
    /// Int32 [H, W, 1]: the splat with the largest blend weight alpha_i T_i at the pixel (the
    /// first of equal ones, front to back) as its index in the cloud given to SetScene; -1
    /// where no splat blends (docs/editing.md "ID images"). Empty unless
    /// CompositeInputs::splat_id.
    t::geometry::Image splat_id;
    RenderStats stats;
};

/// Optional inputs to the composite stage.
struct CompositeInputs {
    /// Float32 [H, W, 1] view-space z of opaque scene geometry (meshes), or empty for none.
    /// A splat is skipped at a pixel when its depth is greater than the scene depth there;
    /// values <= 0 mean no geometry at that pixel (as Filament's cleared depth does).
    const t::geometry::Image* scene_depth = nullptr;
    /// False: GPU backends composite without copying the images to the host (`output`'s
    /// images are left as they were); the CPU backend ignores it. Benchmarks time frames
    /// this way so that the GPU is not left idle, its clocks falling, during the copies.
    bool read_back = true;
    /// The depth images to produce. GPU backends then skip the other's arithmetic for every
    /// blended splat: a colour-only composite took 8-10% less GPU time on an H100.
    bool expected_depth = true;
    bool median_depth = true;
    /// The ID image of RenderOutput::splat_id: one comparison per blended splat on GPUs.
    bool splat_id = false;
};

/// What RenderBatch produces for each view.
struct BatchOptions {
    /// Copy the images to host memory. False leaves them on the device (the returned
    /// outputs carry stats only): benchmarks of the GPU side.
    bool read_back = true;
    /// Colour as UInt8 [H, W, 4] (the float result converted to 8-bit unorm by the device's
    /// rounding; the CPU backend rounds to nearest) instead of Float32 [H, W, 4]: a quarter
    /// of the bytes to copy.
    bool color_uint8 = false;
    bool expected_depth = false;
    bool median_depth = false;
    /// With read_back: the colours go here instead of RenderOutput::color (left empty), view
    /// i at color_destination + i * H * W * 4 * (4 bytes, or 1 with color_uint8), in the
    /// caller's memory (a numpy array from Python): no image per view is allocated and the
    /// colour is copied once, straight from the readback buffer.
    uint8_t* color_destination = nullptr;
    /// With read_back, optional: memory the colours go into, view i at
    /// color_destination + i * (view bytes) when color_destination points inside it, at
    /// Data() + i * (view bytes) when color_destination is null. The Vulkan backend lets the
    /// device write straight into it (RGBA32F from the composite, RGBA8 by a copy; no copy on
    /// the host); other backends copy into it as into any memory. The views must fit in it.
    BatchHostMemory color_memory;
};

/// Where BatchOptions puts the colours of a batch of `views` views of `view_bytes` each:
/// color_destination, else color_memory's start, else nullptr (into RenderOutput::color).
/// Throws core::Open3DError when they would not fit in color_memory.
uint8_t* BatchColorDestination(const BatchOptions& options, size_t views, size_t view_bytes);

class GaussianSplatBackend {
public:
    virtual ~GaussianSplatBackend() = default;

    /// Registered name, e.g. "cpu".
    virtual std::string GetName() const = 0;

    /// Lifecycle: takes (a copy of or a GPU upload of) the splat scene. Throws
    /// core::Open3DError when the cloud is not a valid Gaussian splat cloud.
    virtual void SetScene(const t::geometry::PointCloud& cloud) = 0;
    /// Lifecycle: drops the scene and every per-view buffer.
    virtual void ReleaseResources() = 0;

    /// Geometry stage for one view: project, emit per-tile entries, sort by (tile, depth).
    virtual void RenderGeometryStage(const camera::PinholeCamera& camera,
                                     const RenderConfig& config) = 0;
    /// Composite stage: composite the sorted tiles of the last geometry stage into `output`
    /// (images are (re)allocated to the view size). Throws when no geometry stage ran.
    virtual void RenderCompositeStage(RenderOutput& output, const CompositeInputs& inputs = {}) = 0;
    /// Waits up to `timeout_ms` for a geometry stage that still runs on the device; true
    /// once none does. Backends that finish RenderGeometryStage before returning (the CPU
    /// reference) return true at once. The viewer waits in slices so that a close asked for
    /// meanwhile stops the frame before its composite.
    virtual bool WaitGeometryStage(double timeout_ms) {
        (void)timeout_ms;
        return true;
    }

    /// Hides splats without a new upload: bit i of word i / 32 shows splat i
    /// ([ceil(N / 32)] words; empty shows all). Backends without a mask return false and
    /// the caller rebuilds the scene from the visible splats instead.
    virtual bool SetVisibilityMask(const std::vector<uint32_t>& mask) {
        (void)mask;
        return false;
    }

    /// The scene as the nodes of `hierarchy`, built from `source`, each frame drawing the
    /// view's level-of-detail cut under RenderConfig::lod_budget or lod_target_ms (docs/lod.md);
    /// a budget of 0 draws every leaf, `source` exactly. Returns false, the scene unchanged,
    /// where the backend draws no hierarchy (the default; the Vulkan backend does).
    virtual bool SetSceneHierarchy(const t::geometry::PointCloud& source,
                                   const t::geometry::SplatHierarchy& hierarchy) {
        (void)source;
        (void)hierarchy;
        return false;
    }

    /// Streaming (docs/streaming.md): a scene of `capacity` splat slots of SH degree
    /// `sh_degree`, every one hidden, filled by ApplyStreamStep; `center_min` .. `center_max`
    /// bound every centre that will be written; `compact_storage` stores it at half precision
    /// (frames must then ask for RenderConfig::compact_storage). Backends without a pool (the
    /// default) throw core::Open3DError naming themselves.
    virtual void SetScenePool(int64_t capacity, int sh_degree, const Eigen::Vector3d& center_min,
                              const Eigen::Vector3d& center_max, bool compact_storage = false);
    /// Writes a SplatStreamer step's pages into the pool and shows its cut.
    virtual void ApplyStreamStep(const SplatStreamStep& step);
    /// The most splats a scene or pool may hold on this backend's device (what one storage
    /// binding spans); the largest int64_t where nothing but memory bounds it.
    virtual int64_t MaxSceneSplats() const { return std::numeric_limits<int64_t>::max(); }

    /// Both stages with the images read back. GPU backends may record and submit both in one
    /// go (the Vulkan backend does unless `inputs` has a scene depth); the result equals
    /// RenderGeometryStage + RenderCompositeStage.
    virtual RenderOutput Render(const camera::PinholeCamera& camera, const RenderConfig& config,
                                const CompositeInputs& inputs = {});

    /// Renders every camera (all of one size) with one config, in order. Each output equals
    /// Render of that camera with the same images asked for, bit for bit. The Vulkan backend
    /// records many views into one submission and keeps frames in flight; this default
    /// renders them one by one. Throws core::Open3DError when the cameras differ in size.
    virtual std::vector<RenderOutput> RenderBatch(const std::vector<camera::PinholeCamera>& cameras,
                                                  const RenderConfig& config,
                                                  const BatchOptions& options = {});
};

/// Throws core::Open3DError unless every camera has the size of the first.
void CheckBatchCameras(const std::vector<camera::PinholeCamera>& cameras);
/// Float32 [H, W, 4] in [0, 1] to UInt8 [H, W, 4], rounding to nearest (clamped; NaN -> 0).
t::geometry::Image ColorToUInt8(const t::geometry::Image& color);

using GaussianSplatBackendFactory = std::function<std::unique_ptr<GaussianSplatBackend>()>;

/// Adds (or replaces) a backend factory. Higher layers (Vulkan, Metal) register theirs.
void RegisterGaussianSplatBackend(const std::string& name, GaussianSplatBackendFactory factory);
/// Names of the registered backends, sorted ("cpu" and "placeholder" are built in).
std::vector<std::string> GetGaussianSplatBackendNames();
/// Makes a backend by name; throws core::Open3DError naming the known backends otherwise.
std::unique_ptr<GaussianSplatBackend> CreateGaussianSplatBackend(const std::string& name);

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
