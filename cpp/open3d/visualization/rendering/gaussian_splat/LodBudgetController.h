// RenderConfig::lod_target_ms: the level-of-detail budget that holds a frame time
// (docs/lod.md "A budget that holds a frame time"). Each frame renders with the budget this
// chooses; its GPU time comes back through Observe, and the next budget scales the last one by
// (target / time)^gain, within a factor of two per frame, inside a band of +-3% around the
// target where it stays put (so a still camera keeps its cut and the geometry stage can be
// reused). GPU time grows with the cut's node count plus a fixed part, so the step converges to
// the budget whose frame takes the target without knowing either.
#pragma once

#include <cstdint>

namespace open3d {
namespace visualization {
namespace rendering {

class LodBudgetController {
public:
    /// Budgets are quantized to 1/32 of an octave (2.2% apart): a budget that hovers does not
    /// change the recording every frame.
    static constexpr double kStepsPerOctave = 32.0;
    /// The relative miss within which the budget stays.
    static constexpr double kDeadBand = 0.03;
    /// The exponent of the step: below 1, so noise in one frame's time moves the budget less.
    static constexpr double kGain = 0.7;

    /// The budget for the next frame of a hierarchy of `leaves` leaves, at most `cap` nodes
    /// (RenderConfig::lod_budget; 0: no cap, every leaf). The first call (or the first after
    /// the leaves changed) starts at the cap, or at a quarter of the leaves without one.
    uint64_t NextBudget(double target_ms, uint64_t leaves, uint64_t cap);
    /// A frame rendered with `budget` nodes took `gpu_ms` of GPU time (not counted: <= 0, or a
    /// frame whose geometry stage was reused, whose time says nothing about the budget).
    void Observe(uint64_t budget, double gpu_ms);
    /// Forgets the state (a new scene).
    void Reset();

    uint64_t LastBudget() const { return budget_; }

private:
    uint64_t leaves_ = 0;
    uint64_t budget_ = 0;  // the budget NextBudget gave last; 0: none yet
    uint64_t observed_budget_ = 0;
    double observed_ms_ = 0;  // the latest observation not yet used; 0: none
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
