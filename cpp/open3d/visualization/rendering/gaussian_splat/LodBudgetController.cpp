#include "open3d/visualization/rendering/gaussian_splat/LodBudgetController.h"

#include <algorithm>
#include <cmath>

namespace open3d {
namespace visualization {
namespace rendering {

namespace {

// The budget on the 1/32-octave grid nearest `value`, within [1, limit].
uint64_t Quantized(double value, uint64_t limit) {
    const double steps =
        std::round(std::log2(std::max(value, 1.0)) * LodBudgetController::kStepsPerOctave);
    const double budget = std::round(std::exp2(steps / LodBudgetController::kStepsPerOctave));
    return std::clamp<uint64_t>(static_cast<uint64_t>(budget), 1, limit);
}

}  // namespace

uint64_t LodBudgetController::NextBudget(double target_ms, uint64_t leaves, uint64_t cap) {
    const uint64_t limit = std::max<uint64_t>(1, cap > 0 ? std::min(cap, leaves) : leaves);
    if (leaves != leaves_ || budget_ == 0) {
        Reset();
        leaves_ = leaves;
        budget_ = cap > 0 ? limit : Quantized(double(leaves) / 4.0, limit);
        return budget_;
    }
    if (observed_ms_ > 0.0 && target_ms > 0.0) {
        const double ratio = target_ms / observed_ms_;
        if (std::abs(ratio - 1.0) > kDeadBand) {
            // The step scales the budget the observed frame had (frames in flight may have
            // moved budget_ since), by at most a factor of two either way.
            const double factor = std::clamp(std::pow(ratio, kGain), 0.5, 2.0);
            uint64_t next = Quantized(double(observed_budget_) * factor, limit);
            // Below ~45 nodes a grid step is less than one node: the rounding must not undo
            // the step (a budget of 1 whose frame beat the target stayed at 1 on an H100).
            if (factor > 1.0 && next <= observed_budget_) next = observed_budget_ + 1;
            if (factor < 1.0 && next >= observed_budget_ && observed_budget_ > 1)
                next = observed_budget_ - 1;
            budget_ = std::clamp<uint64_t>(next, 1, limit);
        }
        observed_ms_ = 0.0;  // each observation steers once
    }
    budget_ = std::min(budget_, limit);
    return budget_;
}

void LodBudgetController::Observe(uint64_t budget, double gpu_ms) {
    if (!(gpu_ms > 0.0) || budget == 0) return;
    observed_budget_ = budget;
    observed_ms_ = gpu_ms;
}

void LodBudgetController::Reset() {
    leaves_ = 0;
    budget_ = 0;
    observed_budget_ = 0;
    observed_ms_ = 0.0;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
