// The Vulkan compute backend ("vulkan"): uploads a splat scene once, then renders views
// headless with geometry stage (GaussianGeometryStage) and composite stage
// (GaussianCompositeStage), reads the images back and reports GPU time per pass.
//
// Two paths. The submission path (Render, RenderBatch, SubmitBatch / WaitBatch) records both
// stages of one or many views into one command buffer per frame slot, submits it once and
// keeps up to GetFramesInFlight() frames on the GPU; a recording is submitted again while
// scene, config, size and outputs are unchanged (FrameSlot.h). The stage path
// (RenderGeometryStage, then RenderCompositeStage or the Filament integration's
// RenderCompositeToInterop through a CompositeSink) submits the geometry stage early so GL
// work overlaps it, and skips it when scene, camera and config are unchanged
// (RenderConfig::reuse_geometry).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/LodBudgetController.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Commands.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/DeferredRelease.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/FrameSlot.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianCompositeStage.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianGeometryStage.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianGeometryStageResources.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GpuTimestamps.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Image.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanBackendRegistry.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

/// Where a composite goes and what is recorded around it: the readback images of
/// RenderCompositeStage, or the images shared with GL of RenderCompositeToInterop. The
/// backend runs what both share (geometry stage wait, counters, empty-frame skip, entry-buffer
/// growth and retry, flag warnings, stats) and calls these hooks; a retried frame calls the
/// Record* hooks again and ReadBack once.
class CompositeSink {
public:
    /// What the hooks of one frame get.
    struct Frame {
        VkCommandBuffer cmd = VK_NULL_HANDLE;
        /// No tile entry: the targets are cleared (colour to the background, the rest to 0)
        /// with transfer writes instead of being composited.
        bool empty = false;
        /// What writes the targets: the composite's storage writes or the clear.
        VkPipelineStageFlags2 write_stage = VK_PIPELINE_STAGE_2_NONE;
        VkAccessFlags2 write_access = VK_ACCESS_2_NONE;
        /// The backend's R32F expected depth, alpha and median depth (GENERAL during the
        /// frame; the backend transitions them before RecordBefore).
        const Image* depth = nullptr;
        const Image* alpha = nullptr;
        const Image* median = nullptr;
        /// The R32_UINT ID image when the sink's params ask for it (AdjustParams), else null.
        const Image* splat_id = nullptr;
        GaussianCompositeStage* composite_stage = nullptr;
        /// Composite stage's query pool, reset for this frame (time the depth merge with it).
        const GpuTimestamps* timestamps = nullptr;
    };

    virtual ~CompositeSink() = default;
    /// The colour target, the camera's size, RGBA32F or RGBA16F, with STORAGE and
    /// TRANSFER_DST (an empty frame clears it) usage.
    virtual const Image& ColorTarget() const = 0;
    /// Adjusts the composite's parameters (background from the config, no scene depth).
    virtual void AdjustParams(CompositeParams& params) const = 0;
    /// Before the writes: brings the colour target into GENERAL, ready for the frame's
    /// write stage and access, and records uploads or ownership acquires.
    virtual void RecordBefore(const Frame& frame) = 0;
    /// After the writes: depth merges, copies, ownership releases.
    virtual void RecordAfter(const Frame& frame) = 0;
    /// After the frame's fence: reads the results.
    virtual void ReadBack() = 0;
    /// A semaphore the frame's submission waits for before anything runs (another API's
    /// signal, e.g. GL's), or VK_NULL_HANDLE. Asked once per submission; a binary semaphore
    /// must be handed out once per signal.
    virtual VkSemaphore TakeWaitSemaphore() { return VK_NULL_HANDLE; }
    /// A semaphore the frame's submission signals once its commands are done (another API
    /// waits for it before reading the targets, e.g. GL before sampling the colour), or
    /// VK_NULL_HANDLE. Asked once per submission.
    virtual VkSemaphore TakeSignalSemaphore() { return VK_NULL_HANDLE; }
    /// Everything RecordBefore, RecordAfter and AdjustParams depend on, as text: while it (and
    /// what the backend records) stays the same, the last recording is submitted again.
    /// Empty, the default: recorded every frame.
    virtual std::string RecordingKey() const { return {}; }
    /// Whether ReadBack reads what the GPU wrote. A frame that reads nothing and signals a
    /// semaphore is not waited for: the backend waits for its fence before the next use of
    /// what it touches (WaitForComposite).
    virtual bool ReadsBack() const { return true; }
    /// Whether the composite may be submitted behind a geometry stage still running, with no
    /// host wait between them (queue order and the composite's first barrier order them): its
    /// counters are read after the composite's fence, so the frame is not skipped when empty
    /// and entries that outgrow the buffers are found afterwards (a waited frame is then
    /// rendered again, a deferred one grows the buffers for the next frame).
    virtual bool SubmitsBehindGeometry() const { return false; }
};

class GaussianSplatVulkanBackend final : public GaussianSplatBackend {
public:
    /// Uses `context` (owned) for every GPU object. Tile-entry buffers start at
    /// `initial_entry_capacity` entries and grow to what a frame asks for (up to
    /// RenderConfig::max_tile_entries_total): that frame is rendered again, once.
    explicit GaussianSplatVulkanBackend(std::unique_ptr<VulkanContext> context,
                                        uint32_t initial_entry_capacity = 1u << 22);
    ~GaussianSplatVulkanBackend() override;

    std::string GetName() const override { return "vulkan"; }
    void SetScene(const t::geometry::PointCloud& cloud) override;
    void ReleaseResources() override;
    void RenderGeometryStage(const camera::PinholeCamera& camera,
                             const RenderConfig& config) override;
    bool WaitGeometryStage(double timeout_ms) override;
    void RenderCompositeStage(RenderOutput& output, const CompositeInputs& inputs = {}) override;

    /// One submission for both stages (the stage path when `inputs` has a scene depth).
    RenderOutput Render(const camera::PinholeCamera& camera, const RenderConfig& config,
                        const CompositeInputs& inputs = {}) override;
    /// Splits the cameras into submissions of at most MaxViewsPerSubmission views and keeps
    /// GetFramesInFlight() of them on the GPU while the host copies the previous ones out.
    std::vector<RenderOutput> RenderBatch(const std::vector<camera::PinholeCamera>& cameras,
                                          const RenderConfig& config,
                                          const BatchOptions& options = {}) override;

    /// Submits `cameras` (one size, at most MaxViewsPerSubmission) as one submission and
    /// returns at once with its ticket for WaitBatch. Throws core::Open3DError when they do not
    /// fit or when every frame slot holds a batch that WaitBatch has not collected yet.
    uint64_t SubmitBatch(const std::vector<camera::PinholeCamera>& cameras,
                         const RenderConfig& config, const BatchOptions& options = {});
    /// Waits for the batch of `ticket` and returns its outputs (images when read back, stats
    /// always). A batch whose entries outgrew the slot's buffers is rendered again with larger
    /// ones before it returns. Throws for a ticket that is not pending.
    std::vector<RenderOutput> WaitBatch(uint64_t ticket);

    /// Frame slots of the submission path: 1 (no overlap) to 4; default 2, 1 on a CPU device
    /// (lavapipe), where a second frame competes for the same cores. Waits for the slots'
    /// work and drops what they hold.
    void SetFramesInFlight(int count);
    int GetFramesInFlight() const { return static_cast<int>(slots_.size()); }
    /// Device bytes of per-view images one submission may hold (default 1 GiB).
    void SetBatchBudget(uint64_t bytes);
    /// The most views of `width` x `height` with `options` in one submission (>= 1).
    uint32_t MaxViewsPerSubmission(uint32_t width, uint32_t height,
                                   const BatchOptions& options) const;

    /// The last completed batch (or Render) of the submission path.
    struct BatchStats {
        double gpu_ms = -1.0;  ///< GPU time of its submissions; negative when not measured
        int submissions = 0;   ///< 1, or 2 when it was rendered again with larger buffers
        bool recording_reused = false;
    };
    const BatchStats& GetLastBatchStats() const { return last_batch_; }

    /// The scene as the nodes of `hierarchy` (built from `source`), each frame drawing the
    /// view's level-of-detail cut chosen on the GPU under RenderConfig::lod_budget nodes
    /// (docs/lod.md "The cut on the GPU"); 0, the default, draws every leaf: `source` exactly.
    /// SetScene returns to a plain scene. Throws for an invalid source or hierarchy.
    bool SetSceneHierarchy(const t::geometry::PointCloud& source,
                           const t::geometry::SplatHierarchy& hierarchy) override;
    /// Throws, naming the numbers and how many splats would fit, unless a hierarchy over
    /// `num_leaves` splats of SH degree `sh_degree` can fit in device memory in place of the
    /// present scene. Counts the least any hierarchy takes (its leaves and one inner node),
    /// so it can run before the hierarchy is built: a 98M-splat grid once built for 90 s and
    /// then failed in the driver with VK_ERROR_OUT_OF_DEVICE_MEMORY.
    void CheckHierarchyFits(int64_t num_leaves, int sh_degree) const;
    /// The device bytes CheckHierarchyFits counts: what any hierarchy over `num_leaves`
    /// splats takes at least, with one frame's buffers (no tile entries).
    uint64_t MinHierarchyDeviceBytes(int64_t num_leaves, int sh_degree) const;

    /// A scene of `capacity` splat slots at SH degree `sh_degree`, every one hidden, whose
    /// splats arrive by WriteSceneSplats and are shown by SetVisibility: the pool a
    /// SplatStreamer streams a paged file into (docs/streaming.md). Stored exactly (float32),
    /// or at half precision with `compact_storage`, and kept on the GPU only: there is no
    /// host copy to re-pack, so a frame whose RenderConfig::compact_storage differs throws.
    /// The depth range starts from `center_min` .. `center_max`, the bounds of every centre
    /// that will be written. Throws for a capacity outside 1 .. 2^32 - 1 or a degree outside
    /// 0..3.
    void SetScenePool(int64_t capacity, int sh_degree, const Eigen::Vector3d& center_min,
                      const Eigen::Vector3d& center_max, bool compact_storage = false) override;
    /// Writes `splats` (valid, of the scene's SH degree) over splats [first, first + n) of the
    /// scene, on the GPU and in the copy kept for re-packing, after the frames that read the
    /// scene complete. The visibility mask is unchanged. Throws for a range outside the scene,
    /// another SH degree or a scene drawn through its hierarchy.
    void WriteSceneSplats(int64_t first, const t::geometry::PointCloud& splats);

    /// Writes a SplatStreamer step's pages into the pool and shows its cut.
    void ApplyStreamStep(const SplatStreamStep& step) override;
    /// The most splats a scene may have here: what the depth sort takes (SortMaxCount) and the
    /// projection dispatches, an invocation a splat (16.7M on lavapipe: 65,535 workgroups of
    /// 256; 1.07G on an H200). The splats' own words are read by device address.
    int64_t MaxSceneSplats() const override;

    /// Replaces the visibility mask: bit i of word i / 32 shows splat i ([ceil(N / 32)]).
    void SetVisibility(const std::vector<uint32_t>& mask);
    bool SetVisibilityMask(const std::vector<uint32_t>& mask) override {
        SetVisibility(mask);
        return true;
    }

    /// The most tile entries a frame of `config` may allocate: what the config allows, within
    /// what the scan (saturating at shader::kScanSaturation) and the sorts (`sort_max_count`:
    /// SortMaxCount) address. Entry buffers never grow past it.
    static uint32_t MaxEntryCapacity(const RenderConfig& config, uint32_t sort_max_count);
    /// The most pairs this device's sorts take (RadixSort::MaxCountFor): 1,073,741,823 on an
    /// H200, 33,554,432 on lavapipe.
    uint32_t SortMaxCount() const;

    /// Counters that make the skips visible to tests and benchmarks.
    struct Counters {
        int64_t scene_uploads = 0;         ///< packs + uploads of the scene
        int64_t geometry_runs = 0;         ///< geometry stage recorded
        int64_t geometry_reuses = 0;       ///< geometry stage skipped (nothing changed)
        int64_t composites = 0;            ///< composite stage submitted
        int64_t composite_reuses = 0;      ///< of those, submitted again without recording
        int64_t held_geometry_stages = 0;  ///< geometry stages submitted behind GL's semaphore
        int64_t capacity_growths = 0;      ///< frames re-rendered with larger entry buffers
        int64_t skipped_composites = 0;    ///< frames with no tile entry: images cleared instead
        int64_t submissions = 0;           ///< submission path: command buffers submitted
        int64_t recordings = 0;            ///< submission path: command buffers recorded
        int64_t deferred_releases = 0;     ///< resources retired while frames were in flight
        int64_t host_imports = 0;          ///< BatchHostMemory blocks imported
        int64_t host_import_releases = 0;  ///< imports dropped after their memory's last user
    };
    const Counters& GetCounters() const { return counters_; }
    const VulkanContext& GetContext() const { return *context_; }

    /// Composite stage of the last geometry stage into `sink` (RenderCompositeStage and
    /// RenderCompositeToInterop); returns the frame's stats. Throws core::Open3DError when no
    /// Geometry stage ran or the sink's colour target is not the camera's size.
    RenderStats RenderComposite(CompositeSink& sink);
    /// Waits for a composite submitted without a host wait (CompositeSink::ReadsBack false
    /// with a signal semaphore); its GPU time becomes the next such frame's gpu_composite_ms.
    /// Whoever frees a sink's targets calls it first.
    void WaitForComposite();

private:
    class ReadbackSink;

    // Submission path (GaussianSplatVulkanBackendSlots.cpp: slots and recordings;
    // GaussianSplatVulkanBackendFrames.cpp: submission, batches, readback).
    FrameSlot& AcquireSlot();
    void PrepareSlot(FrameSlot& slot, const FrameRecordingKey& key);
    void RecordSlot(FrameSlot& slot, const FrameRecordingKey& key);
    /// The slot's recordings (current and spare) may no longer be submitted.
    static void ForgetRecordings(FrameSlot& slot);
    /// Makes slot.cmd a recording of `key`: the current one, a spare, or a new recording (the
    /// current one kept as a spare). Returns whether no recording was made.
    bool UseRecording(FrameSlot& slot, const FrameRecordingKey& key);
    /// Records the slot's copies to host memory, the colours to `color_target` at
    /// `color_offset`.
    void RecordReadback(FrameSlot& slot, VkBuffer color_target, VkDeviceSize color_offset);
    void SubmitSlot(FrameSlot& slot);
    void WaitSlot(FrameSlot& slot);
    void WaitAllSlots();
    FrameRecordingKey MakeKey(const std::vector<camera::PinholeCamera>& cameras,
                              const RenderConfig& config, const BatchOptions& options,
                              uint32_t entry_capacity) const;
    void EnsureScenePrecision(const RenderConfig& config);
    // BatchHostMemory the device writes colours into (VK_EXT_external_memory_host), kept
    // imported while the caller holds the memory and frames in flight still write it.
    struct HostImport {
        BatchHostMemory memory;
        Buffer buffer;
        uint64_t last_serial = 0;  ///< the last submission that writes it
    };
    /// The import of `memory`, made on first use; nullptr when the context cannot import
    /// it (then the colours are copied on the host as into any memory).
    HostImport* ImportHostMemory(const BatchHostMemory& memory);
    /// Drops the imports whose memory nobody else holds and no frame in flight writes (every
    /// submission checks, so a dropped BatchHostMemory is freed by the next one).
    void ReleaseUnusedImports();
    void RetireSceneBuffers(bool visibility_only);
    /// Drops the hierarchy's nodes (kept until frames in flight complete).
    void RetireLod();
    bool AnySlotBusy() const;
    /// Logs each error flag the first time a frame reports it.
    void WarnNewFlags(uint32_t flags);

    /// RenderConfig::lod_target_ms: `config` with the budget lod_controller_ chooses for this
    /// frame where the scene is a hierarchy and a target is set, else `config` as it is.
    RenderConfig WithLodTarget(const RenderConfig& config);
    /// A frame rendered with `frame_config` (WithLodTarget's) took `gpu_ms` of GPU time.
    void ObserveLodFrame(const RenderConfig& frame_config, double gpu_ms);

    void UploadScene(SplatPrecision precision);
    /// WriteSceneSplats of several ranges, checked first, written in one submission.
    void WriteSceneSplatRanges(
        const std::vector<std::pair<int64_t, const t::geometry::PointCloud*>>& ranges);
    void EnsureViewBuffers(uint32_t entry_capacity);
    /// Refuses a view size whose images cannot fit in device memory, naming a size that
    /// would (checked before the geometry stage, so nothing is half made).
    void CheckViewFits(uint32_t width, uint32_t height) const;
    void EnsureTargets(uint32_t width, uint32_t height);
    void EnsureReadback(uint32_t width, uint32_t height);
    void WaitForGeometry();
    /// The composite's commands for `sink` into `cmd` (begun): barriers, the sink's hooks, the
    /// composite or, for an empty frame, the clears.
    void RecordCompositeFrame(CompositeSink& sink, VkCommandBuffer cmd,
                              const CompositeParams& params, bool empty);
    /// The stage path's submissions (geometry and composite) complete before their buffers
    /// change.
    void WaitForStageWork();
    /// Submits a geometry stage held for the next composite (geometry_held_), waiting for
    /// `wait` (VK_NULL_HANDLE: nothing) before it runs.
    void SubmitHeldGeometry(VkSemaphore wait);
    /// A frame's counts and flags from its geometry stage's counters, and the scene's bytes.
    void FillCounterStats(const shader::GaussianGeometryStageCounters& counters,
                          RenderStats& stats) const;
    /// The finished geometry stage's counters (keeps them as last_counters_ and whether they
    /// left room for a composite behind the next geometry stage).
    shader::GaussianGeometryStageCounters ReadStageCounters();
    /// Whether the allocation, not the config, cut the frame of `counters` short and the
    /// entry buffers may grow.
    bool EntriesOutgrewBuffers(const shader::GaussianGeometryStageCounters& counters) const;
    /// The entry capacity for the request of `counters` plus a quarter (so a moving camera
    /// does not regrow every frame), within what the config and the sort allow.
    uint32_t GrownEntryCapacity(const shader::GaussianGeometryStageCounters& counters) const;
    /// Grows the entry buffers to GrownEntryCapacity(counters) and renders the last geometry
    /// stage and `sink`'s composite again; returns that frame's stats.
    RenderStats RenderAgainWithGrownBuffers(CompositeSink& sink,
                                            const shader::GaussianGeometryStageCounters& counters);

    std::unique_ptr<VulkanContext> context_;
    CommandPool pool_;
    std::unique_ptr<CommandPool> transfer_pool_;  ///< when the context has a transfer queue
    GaussianGeometryStage geometry_stage_;
    GaussianCompositeStage composite_stage_;
    GpuTimestamps geometry_stage_timestamps_;
    GpuTimestamps composite_stage_timestamps_;
    Counters counters_;
    LodBudgetController lod_controller_;

    // The scene: kept on the CPU to re-pack when the storage precision changes.
    std::optional<t::geometry::PointCloud> cloud_;
    /// SetScenePool's scene: buffers written page by page, no host copy (cloud_ is empty).
    bool pool_scene_ = false;
    std::vector<uint32_t> visibility_mask_;
    GeometryStageResources geometry_stage_resources_;
    Buffer counters_readback_;
    Buffer composite_state_;

    // Composite stage's R32F images (every composite; alpha is for the interop's depth merge),
    // RenderCompositeStage's RGBA32F colour and the readback buffers of what it returns.
    uint32_t width_ = 0, height_ = 0;
    Image depth_, alpha_, median_;
    Image color_;
    Buffer color_readback_, depth_readback_, median_readback_;
    // The ID image and its readback, made on the first composite that asks for one.
    Image splat_id_;
    Buffer splat_id_readback_;

    // The last geometry stage: what it rendered, and its command buffer while in flight.
    struct GeometryState {
        camera::PinholeCamera camera;
        RenderConfig config;
        bool valid = false;
        bool in_flight = false;
        bool reused = false;
        /// The geometry stage left each tile's range in composite_state_
        /// (GaussianGeometryStage::WritesTileRanges): the composite reads them as they are.
        bool tile_ranges_written = false;
        /// Geometry stage's times as a frame reports them: geometry_ms, gpu_project_ms,
        /// gpu_sort_ms and its parts (the rest stays 0).
        RenderStats times;
    } geometry_;
    // Recorded once per FrameRecordingKey (one view) and submitted again with the camera
    // written into stage_params_upload_.
    CommandBuffer geometry_stage_cmd_;
    UniqueFence geometry_stage_fence_;
    // The last composite's recording (submitted again while its key stays), its fence, and
    // whether it is in flight without a host wait (until WaitForComposite).
    CommandBuffer composite_cmd_;
    UniqueFence composite_fence_;
    std::string composite_recorded_;  ///< its key; empty: never reused
    bool composite_in_flight_ = false;
    bool composite_in_flight_empty_ = false;
    /// The composite in flight was submitted behind its geometry stage: its counters are read
    /// once its fence is waited for.
    bool composite_counters_pending_ = false;
    double last_composite_gpu_ms_ = 0.0;
    /// The last counters read, and whether they left a quarter of the entry buffers free
    /// (a composite may then be submitted behind the next geometry stage).
    shader::GaussianGeometryStageCounters last_counters_{};
    bool entries_have_room_ = false;
    /// The last composite waited for another API's semaphore (GL's "mesh drawn"): the next
    /// geometry stage is recorded but held (geometry_held_) and submitted by the composite,
    /// behind that semaphore, so that a frame's Vulkan work runs on the GPU as one block
    /// after GL's and the GPU switches between the APIs once each way per frame. Any wait
    /// for the geometry stage submits it first.
    bool hold_geometry_submit_ = false;
    bool geometry_held_ = false;
    /// OPEN3D_VULKAN_HOLD_GEOMETRY=0 submits every geometry stage at once, for measurements.
    bool hold_geometry_enabled_ = true;
    Buffer stage_params_upload_;
    FrameRecordingKey stage_recorded_;
    bool stage_recording_valid_ = false;
    uint32_t warned_flags_ = 0;
    uint32_t initial_entry_capacity_ = 0;
    bool growing_ = false;

    std::vector<std::unique_ptr<FrameSlot>> slots_;
    std::vector<std::unique_ptr<HostImport>> host_imports_;
    bool host_import_failed_ = false;  ///< warned once; later blocks are copied on the host
    /// RGBA32F batches into imported memory are composited straight into it (SubmitBatch);
    /// OPEN3D_VULKAN_COMPOSITE_TO_HOST=0 copies them instead, for measurements.
    const bool composite_to_host_ = EnvironmentSwitchOn("OPEN3D_VULKAN_COMPOSITE_TO_HOST");
    /// Whether the slot's recording reads back through the transfer queue.
    bool UsesTransfer(const FrameSlot& slot) const {
        return slot.recorded.options.read_back && context_->HasTransferQueue();
    }
    DeferredReleaseQueue deferred_;
    uint64_t next_serial_ = 1;       ///< serial of the next submission of the submission path
    uint64_t completed_serial_ = 0;  ///< every submission up to it has completed
    uint64_t scene_serial_ = 1;      ///< bumped by every scene upload (recordings bind buffers)
    uint64_t batch_budget_ = uint64_t(1) << 30;
    BatchStats last_batch_;
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
