#include "open3d/visualization/rendering/gaussian_splat/SplatStreamSession.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"

namespace open3d {
namespace visualization {
namespace rendering {

namespace {

std::string Count(int64_t n) {
    if (n >= 1000000) return fmt::format("{:.1f}M", n / 1e6);
    if (n >= 10000) return fmt::format("{:.0f}k", n / 1e3);
    return std::to_string(n);
}

bool SameView(const camera::PinholeCamera& a, const camera::PinholeCamera& b) {
    return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
           a.cx == b.cx && a.cy == b.cy && a.world_to_camera == b.world_to_camera;
}

}  // namespace

std::string FormatStreamProgress(const SplatStreamProgress& p) {
    std::string line = fmt::format(
        "Streaming: {} of {} pages in the pool of {}, {:.2f} GB read, {} splats drawn",
        p.resident_pages, p.file_pages, p.pool_pages, p.bytes_read / 1e9, Count(p.nodes_drawn));
    if (!p.error.empty()) return line + "; stopped: " + p.error;  // (settled)
    if (p.starved) return line + ", pool full";
    if (p.settled && p.pages_wanted == 0) return line + ", complete";
    if (p.pages_wanted > 0) line += fmt::format(", {} pages wanted", p.pages_wanted);
    return line;
}

uint64_t ParseByteSize(const std::string& text, const std::string& what) {
    return core::ParseByteCount(text, what);
}

uint64_t ParseGpuBudget(const std::string& text, const std::string& what) {
    return text == "auto" ? 0 : ParseByteSize(text, what);
}

double StreamPoolBytesPerSplat(int sh_degree, bool compact_storage) {
    return PackedSplatLayout(sh_degree, SplatPrecisionFor(compact_storage)).BytesPerSplat() +
           1.0 / 8.0;
}

int64_t StreamPoolPages(const t::io::SplatPageFile& file, uint64_t gpu_budget, int64_t max_splats,
                        bool compact_storage) {
    const double per_splat = StreamPoolBytesPerSplat(file.ShDegree(), compact_storage);
    const int64_t capacity = file.PageCapacity();
    const int64_t most = max_splats / capacity;  // pages the backend holds
    if (most < 1) {
        core::ThrowError("this device holds at most {} splats in one scene, not one page of {}",
                         max_splats, capacity);
    }
    const double budget = gpu_budget > 0 ? double(gpu_budget) : double(uint64_t(1) << 30);
    // Every page has a slot at most: a budget above the file's size asks for no more.
    const int64_t pages =
        std::min(static_cast<int64_t>(budget / (per_splat * double(capacity))), file.NumPages());
    if (pages > most) {
        if (gpu_budget > 0) {
            core::ThrowError(
                "a GPU budget of {} bytes makes a pool of {} splats; this device holds at most "
                "{} splats in one scene ({:.0f} bytes of pages of {}): give a smaller budget, or "
                "0 for the most it holds",
                gpu_budget, pages * capacity, max_splats, double(most * capacity) * per_splat,
                capacity);
        }
        return most;
    }
    if (pages < 1) {
        core::ThrowError(
            "a GPU budget of {} bytes holds no page of {} splats ({:.0f} bytes a splat): at "
            "least {:.0f} bytes",
            budget, file.PageCapacity(), per_splat,
            std::ceil(per_splat * double(file.PageCapacity())));
    }
    return pages;
}

namespace {

// The cut's budget: options.splat_budget, or 0 for what a pool of `pool_splats` holds.
int64_t CutBudget(const SplatStreamOptions& options, int64_t pool_splats) {
    if (options.splat_budget < 0) {
        core::ThrowError("streaming: a splat budget of {} (0: as many as the pool holds)",
                         options.splat_budget);
    }
    return options.splat_budget > 0 ? options.splat_budget : pool_splats;
}

}  // namespace

SplatStreamSession::SplatStreamSession(const std::string& path, const SplatStreamOptions& options,
                                       int64_t max_splats)
    : file_(path),
      compact_storage_(options.compact_storage),
      pool_pages_(StreamPoolPages(file_, options.gpu_budget, max_splats, options.compact_storage)),
      streamer_(file_, pool_pages_, CutBudget(options, pool_pages_ * file_.PageCapacity())),
      worker_(streamer_, options.reads_per_step) {
    progress_.path = path;
    progress_.file_pages = file_.NumPages();
    progress_.pool_pages = streamer_.PoolPages();
}

SplatStreamSession::~SplatStreamSession() = default;

void SplatStreamSession::SetView(const camera::PinholeCamera& camera) {
    if (view_ && SameView(*view_, camera)) return;
    view_ = camera;
    worker_.SetView(SplatCutViewOf(camera));
}

std::optional<SplatStreamStep> SplatStreamSession::Take() {
    std::optional<SplatStreamStep> step = worker_.Take();
    if (step) {
        progress_.resident_pages = step->resident_pages;
        progress_.pages_read = step->pages_read;
        progress_.bytes_read = step->bytes_read;
        progress_.evictions = step->evictions;
        progress_.nodes_drawn = step->cut_nodes;
        progress_.pages_wanted = step->pages_wanted;
        progress_.starved = step->starved;
    }
    return step;
}

SplatStreamProgress SplatStreamSession::Progress() const {
    SplatStreamProgress p = progress_;
    // Before the first view nothing was streamed. Resting is asked first: a resting worker
    // makes no step, so nothing can become pending after. A worker stopped by an error steps
    // no more whatever the view (it is not resting after a new view).
    p.error = worker_.Error();
    p.settled = view_.has_value() && (!p.error.empty() || worker_.Idle()) && !worker_.Pending();
    return p;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
