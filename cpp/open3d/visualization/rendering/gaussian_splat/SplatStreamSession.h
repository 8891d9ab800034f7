// A paged splat file streamed into a backend's pool for the views a renderer draws
// (docs/streaming.md "In the renderer and the viewer"): the file, its streamer, and the
// worker that steps the streamer off the render thread. GaussianSplatRenderer::StreamSplats
// makes one; the render thread gives it each new view and takes what the steps changed.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/io/SplatPageFile.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamWorker.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamer.h"

namespace open3d {
namespace visualization {
namespace rendering {

struct SplatStreamOptions {
    /// GPU memory of the pool in bytes (packed exact splats and their visibility bits): the
    /// pool holds as many whole pages as fit (at least one, at most the file's). 0: 1 GiB, or as
    /// many pages as the backend holds in one scene where that is less (lavapipe: 16.7M splats).
    uint64_t gpu_budget = 0;
    /// Nodes a cut may draw; 0: as many as the pool holds (a budget that cannot bind).
    int64_t splat_budget = 0;
    /// Pages read and checked per streaming step (a step's pages show together).
    int64_t reads_per_step = 16;
    /// The pool at half precision (RenderConfig::compact_storage's packing: 84 instead of 152
    /// bytes a splat at SH degree 2, so 1.8 times the splats in a budget). A pool keeps the
    /// precision it is made at: the stream's frames draw at it whatever their
    /// RenderConfig::compact_storage says.
    bool compact_storage = false;
};

/// Where a stream stands, as of the last step the render thread took.
struct SplatStreamProgress {
    std::string path;
    int64_t file_pages = 0;      ///< pages in the file
    int64_t pool_pages = 0;      ///< page slots of the pool
    int64_t resident_pages = 0;  ///< pages in the pool
    int64_t pages_read = 0;      ///< page reads so far (a page evicted and read again: twice)
    uint64_t bytes_read = 0;
    int64_t evictions = 0;
    int64_t nodes_drawn = 0;   ///< by the newest cut
    int64_t pages_wanted = 0;  ///< pages the newest cut would open into and lacks
    bool starved = false;      ///< a wanted page found no slot: the pool is full for this view
    /// Nothing more will change for the newest view: the worker rests (or stopped on an
    /// error) and its last step has been taken (shown by the frame that took it).
    bool settled = false;
    std::string error;  ///< why streaming stopped (a page the file refused), else empty
};

/// One line for a panel or a log: "Streaming: 12 of 487 pages in the pool of 49, 0.21 GB
/// read, 1.2M splats drawn, 30 pages wanted" (or "..., complete", "..., pool full",
/// "...; stopped: WHY").
std::string FormatStreamProgress(const SplatStreamProgress& progress);

/// Bytes from "2G", "512M", "1.5G", "123456": core::ParseByteCount, the one parser of sizes
/// (K, M, G, T are powers of 1024). Throws core::Open3DError naming `what` (the flag) and
/// the text when it is not one.
uint64_t ParseByteSize(const std::string& text, const std::string& what = "size");
/// SplatStreamOptions::gpu_budget from text: "auto" is 0 (the default pool), anything else
/// ParseByteSize's bytes.
uint64_t ParseGpuBudget(const std::string& text, const std::string& what = "gpu_budget");

/// Bytes a splat of SH degree `sh_degree` takes in a pool: its packed words (exact, or half
/// precision with `compact_storage`) and its visibility bit.
double StreamPoolBytesPerSplat(int sh_degree, bool compact_storage = false);

/// Page slots a pool of `gpu_budget` bytes (0: SplatStreamOptions' default) holds for `file`
/// on a backend that holds at most `max_splats` splats in a scene, and no more than the file
/// has pages (at half precision with `compact_storage`). Throws core::Open3DError
/// naming the sizes when it holds no page, or when a given budget makes a pool larger than
/// the backend holds.
int64_t StreamPoolPages(const t::io::SplatPageFile& file, uint64_t gpu_budget,
                        int64_t max_splats = std::numeric_limits<int64_t>::max(),
                        bool compact_storage = false);

class SplatStreamSession {
public:
    /// Opens `path` (checking its header and page table) and starts the worker, idle until
    /// the first view, for a pool of at most `max_splats` splats (the backend's
    /// MaxSceneSplats). Throws core::Open3DError for a refused file or options.
    SplatStreamSession(const std::string& path, const SplatStreamOptions& options,
                       int64_t max_splats = std::numeric_limits<int64_t>::max());
    /// Stops the worker after its step in progress.
    ~SplatStreamSession();
    SplatStreamSession(const SplatStreamSession&) = delete;
    SplatStreamSession& operator=(const SplatStreamSession&) = delete;

    const t::io::SplatPageFile& File() const { return file_; }
    /// Splat slots of the pool (the scene the backend holds).
    int64_t PoolSplats() const { return streamer_.PoolSplats(); }
    /// SplatStreamOptions::compact_storage: the pool's precision.
    bool CompactStorage() const { return compact_storage_; }

    /// Streams for `camera` from the worker's next step on; the same view again changes
    /// nothing (a renderer calls this every frame).
    void SetView(const camera::PinholeCamera& camera);
    /// What the steps since the last Take changed (SplatStreamWorker::Take); updates Progress.
    std::optional<SplatStreamStep> Take();
    /// A step waits to be taken: the next frame's picture differs.
    bool HasNews() const { return worker_.Pending(); }
    SplatStreamProgress Progress() const;

private:
    t::io::SplatPageFile file_;
    const bool compact_storage_;
    const int64_t pool_pages_;  // StreamPoolPages, once
    SplatStreamer streamer_;
    SplatStreamWorker worker_;
    std::optional<camera::PinholeCamera> view_;
    SplatStreamProgress progress_;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
