// Where a presented integrated frame spends its GPU time on GL's side: GL timestamps
// (glQueryCounter) issued on Filament's driver thread at three places of each frame, read
// after the last frame. Between "mesh view done" and "compose done" GL waits for the splats
// (Vulkan's geometry stage and composite, and the GPU's switches between the two APIs).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "open3d/visualization/rendering/filament/FilamentEngine.h"

namespace gs_render {

class GlGpuTimeline {
public:
    enum Point { kFrameBegin = 0, kMeshDone = 1, kComposeDone = 2, kPoints = 3 };

    /// Inactive (Mark does nothing, Describe says why) where RunOnDriverThread cannot run.
    explicit GlGpuTimeline(const open3d::visualization::rendering::FilamentEngine& engine);
    ~GlGpuTimeline();

    /// A timestamp of `point` in frame `frame` (0-based), after every GL command issued so far.
    void Mark(int frame, Point point);
    /// Reads every timestamp (waits for Filament's GL work) and describes the frames from
    /// `first` on as one line of means in milliseconds.
    std::string Describe(int first);

private:
    const open3d::visualization::rendering::FilamentEngine& engine_;
    // Written and read on Filament's driver thread only (query objects are per context).
    std::shared_ptr<std::vector<std::array<uint32_t, kPoints>>> queries_;
};

}  // namespace gs_render
