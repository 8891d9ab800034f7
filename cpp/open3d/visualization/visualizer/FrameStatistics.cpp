#include "open3d/visualization/visualizer/FrameStatistics.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "open3d/core/Percentile.h"

namespace open3d {
namespace visualization {

namespace {

constexpr double kSmoothing = 0.05;  // weight of the newest frame (about 20 frames)

rendering::FrameTimes Mix(const rendering::FrameTimes& old_value,
                          const rendering::FrameTimes& new_value, double w) {
    auto mix = [w](double a, double b) { return (1.0 - w) * a + w * b; };
    rendering::FrameTimes out;
    out.geometry_stage_ms = mix(old_value.geometry_stage_ms, new_value.geometry_stage_ms);
    out.filament_ms = mix(old_value.filament_ms, new_value.filament_ms);
    out.composite_stage_ms = mix(old_value.composite_stage_ms, new_value.composite_stage_ms);
    out.compose_ms = mix(old_value.compose_ms, new_value.compose_ms);
    out.readback_ms = mix(old_value.readback_ms, new_value.readback_ms);
    out.total_ms = mix(old_value.total_ms, new_value.total_ms);
    return out;
}

}  // namespace

void FrameStatistics::Add(double frame_ms, const rendering::FrameTimes& parts) {
    const double w = frame_ms_.empty() ? 1.0 : kSmoothing;
    smoothed_frame_ms_ = (1.0 - w) * smoothed_frame_ms_ + w * frame_ms;
    smoothed_parts_ = Mix(smoothed_parts_, parts, w);
    frame_ms_.push_back(frame_ms);
    parts_.push_back(parts);
}

void FrameStatistics::Clear() {
    frame_ms_.clear();
    parts_.clear();
    smoothed_frame_ms_ = 0.0;
    smoothed_parts_ = {};
}

FrameTimeSummary FrameStatistics::Summarize(int64_t warmup) const {
    FrameTimeSummary summary;
    const int64_t n = GetCount();
    const int64_t first = n > warmup ? warmup : 0;
    summary.frames = n - first;
    if (summary.frames == 0) return summary;
    const std::vector<double> frames(frame_ms_.begin() + first, frame_ms_.end());
    double sum = 0.0;
    for (double v : frames) sum += v;
    summary.mean_ms = sum / summary.frames;
    summary.median_ms = core::Percentile(frames, 0.5);
    summary.p90_ms = core::Percentile(frames, 0.9);
    rendering::FrameTimes& m = summary.mean_parts;
    for (int64_t i = first; i < n; ++i) {
        m.geometry_stage_ms += parts_[i].geometry_stage_ms / summary.frames;
        m.filament_ms += parts_[i].filament_ms / summary.frames;
        m.composite_stage_ms += parts_[i].composite_stage_ms / summary.frames;
        m.compose_ms += parts_[i].compose_ms / summary.frames;
        m.readback_ms += parts_[i].readback_ms / summary.frames;
        m.total_ms += parts_[i].total_ms / summary.frames;
    }
    return summary;
}

std::string FormatSummary(const FrameTimeSummary& s) {
    if (s.frames == 0) return "no frames timed";
    const rendering::FrameTimes& m = s.mean_parts;
    return fmt::format(
        "{} frames: frame time mean {:.2f} ms ({:.1f} fps), median {:.2f} ms, p90 {:.2f} ms; "
        "renderer mean {:.2f} ms (geometry stage {:.2f}, Filament {:.2f}, composite stage {:.2f}, "
        "compose + present {:.2f})",
        s.frames, s.mean_ms, 1000.0 / s.mean_ms, s.median_ms, s.p90_ms, m.total_ms,
        m.geometry_stage_ms, m.filament_ms, m.composite_stage_ms, m.compose_ms);
}

}  // namespace visualization
}  // namespace open3d
