// Frame times of the interactive loop: the wall time between presented frames and the
// renderer's parts (rendering::FrameTimes), kept for a smoothed panel readout and a
// summary at exit (docs/viewer.md "Frame time").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "open3d/visualization/rendering/filament/FilamentRenderer.h"

namespace open3d {
namespace visualization {

struct FrameTimeSummary {
    int64_t frames = 0;  ///< frames summarised (the warm-up frames left out)
    double mean_ms = 0.0, median_ms = 0.0, p90_ms = 0.0;  ///< wall time per frame
    rendering::FrameTimes mean_parts;                     ///< renderer parts, mean
};

class FrameStatistics {
public:
    /// One presented frame: `frame_ms` wall time since the previous one (the whole loop
    /// iteration: events, UI, rendering, presenting), `parts` what the renderer measured.
    void Add(double frame_ms, const rendering::FrameTimes& parts);
    void Clear();
    int64_t GetCount() const { return static_cast<int64_t>(frame_ms_.size()); }
    /// Exponential moving averages (about the last 20 frames), for display.
    double GetSmoothedFrameMs() const { return smoothed_frame_ms_; }
    const rendering::FrameTimes& GetSmoothedParts() const { return smoothed_parts_; }
    /// Statistics of all frames but the first `warmup` (shader compilation, first upload).
    FrameTimeSummary Summarize(int64_t warmup = 3) const;

private:
    std::vector<double> frame_ms_;
    std::vector<rendering::FrameTimes> parts_;
    double smoothed_frame_ms_ = 0.0;
    rendering::FrameTimes smoothed_parts_;
};

/// One line: "N frames: mean X ms (Y fps), median, p90; renderer: geometry stage .., Filament ..".
std::string FormatSummary(const FrameTimeSummary& summary);

}  // namespace visualization
}  // namespace open3d
