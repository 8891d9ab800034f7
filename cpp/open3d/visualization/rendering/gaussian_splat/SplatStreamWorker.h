// A SplatStreamer run on a thread of its own (docs/streaming.md "Off the render thread"): it
// steps for the newest view it was given and keeps what the steps changed until the render
// thread takes it, so cutting and reading pages never hold a frame. The GPU writes stay with
// the render thread: it applies what Take returns (GaussianSplatVulkanBackend::ApplyStreamStep)
// before drawing.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "open3d/visualization/rendering/gaussian_splat/SplatStreamer.h"

namespace open3d {
namespace visualization {
namespace rendering {

class SplatStreamWorker {
public:
    /// Steps `streamer` (which only this worker may use until it is destroyed) with up to
    /// `reads_per_step` page reads a step (the first step reads the root's page alone). It
    /// starts idle: SetView gives it a view.
    SplatStreamWorker(SplatStreamer& streamer, int64_t reads_per_step);
    /// Stops after the step in progress and joins the thread.
    ~SplatStreamWorker();
    SplatStreamWorker(const SplatStreamWorker&) = delete;
    SplatStreamWorker& operator=(const SplatStreamWorker&) = delete;

    /// Steps for `view` from the next step on; the worker rests once a step for it wants no
    /// page or can read none (a full pool), until the view changes.
    void SetView(const t::geometry::SplatCutView& view);
    /// What the steps since the last Take changed, merged: their page writes in order (apply
    /// them in that order: a slot written twice holds the later page) and the newest mask and
    /// counts. Empty when no step completed since. The worker waits while 64 untaken pages
    /// are pending, so an absent render thread does not fill host memory.
    std::optional<SplatStreamStep> Take();
    /// Whether the worker rests: its last step, for the newest view, needs nothing more.
    bool Idle() const;
    /// Whether a step waits to be taken.
    bool Pending() const;
    /// Why streaming stopped (a page the file refused), empty while it has not.
    std::string Error() const;

private:
    void Run();

    SplatStreamer& streamer_;
    const int64_t reads_per_step_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::optional<t::geometry::SplatCutView> view_;
    uint64_t view_serial_ = 0;  // bumped by SetView
    bool resting_ = true;
    bool stop_ = false;
    std::optional<SplatStreamStep> pending_;
    std::string error_;
    std::thread thread_;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
