#include "open3d/visualization/rendering/gaussian_splat/SplatStreamWorker.h"

#include <utility>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"

namespace open3d {
namespace visualization {
namespace rendering {

namespace {
// Untaken page writes at which the worker waits for the render thread.
constexpr size_t kMaxPendingWrites = 64;
}  // namespace

SplatStreamWorker::SplatStreamWorker(SplatStreamer& streamer, int64_t reads_per_step)
    : streamer_(streamer), reads_per_step_(reads_per_step) {
    if (reads_per_step < 1) {
        core::ThrowError("SplatStreamWorker: reads per step must be >= 1, not {}", reads_per_step);
    }
    thread_ = std::thread([this] { Run(); });
}

SplatStreamWorker::~SplatStreamWorker() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
}

void SplatStreamWorker::SetView(const t::geometry::SplatCutView& view) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        view_ = view;
        ++view_serial_;
        resting_ = false;
    }
    wake_.notify_all();
}

std::optional<SplatStreamStep> SplatStreamWorker::Take() {
    std::optional<SplatStreamStep> taken;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        taken.swap(pending_);
    }
    wake_.notify_all();  // a worker waiting for room may go on
    return taken;
}

bool SplatStreamWorker::Idle() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return resting_;
}

bool SplatStreamWorker::Pending() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return pending_.has_value();
}

std::string SplatStreamWorker::Error() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return error_;
}

void SplatStreamWorker::Run() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (true) {
        wake_.wait(lock, [&] {
            return stop_ || (error_.empty() && !resting_ && view_ &&
                             (!pending_ || pending_->writes.size() < kMaxPendingWrites));
        });
        if (stop_) return;
        const t::geometry::SplatCutView view = *view_;
        const uint64_t serial = view_serial_;
        lock.unlock();
        SplatStreamStep step;
        try {
            // The first step reads the root's page alone: the first picture as early as can be.
            step = streamer_.Step(view, streamer_.PagesRead() == 0 ? 0 : reads_per_step_);
        } catch (const std::exception& e) {
            // A page the file refuses: the picture stays as it is, the error is logged and kept,
            // and the worker steps no more.
            lock.lock();
            resting_ = true;
            error_ = e.what();
            core::LogWarning("streaming stopped: {}", e.what());
            continue;
        }
        lock.lock();
        const bool done = step.pages_wanted == 0 || (step.starved && step.writes.empty());
        if (serial == view_serial_ && done) resting_ = true;
        if (pending_) {
            // A slot written again replaces its earlier write (one submission's copies must
            // not overlap).
            std::vector<SplatStreamStep::PageWrite>& writes = pending_->writes;
            for (SplatStreamStep::PageWrite& write : step.writes) {
                std::erase_if(writes, [&](const SplatStreamStep::PageWrite& earlier) {
                    return earlier.first_splat == write.first_splat;
                });
                writes.push_back(std::move(write));
            }
            step.writes = std::move(pending_->writes);
            step.pages_evicted += pending_->pages_evicted;
            step.cut_ms += pending_->cut_ms;
            step.read_ms += pending_->read_ms;
        }
        pending_ = std::move(step);
    }
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
