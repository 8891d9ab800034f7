// LodBudgetController (RenderConfig::lod_target_ms) against a model of a device whose frame
// takes a fixed part plus a part per cut node, with noise, frames in flight and a scene whose
// cost changes: the budget it chooses must bring the frame to the target and keep it there.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <utility>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/LodBudgetController.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

namespace open3d {
namespace tests {
namespace {

using visualization::rendering::LodBudgetController;

// A frame's GPU time for `budget` nodes: fixed + per_node x budget, times a noise factor.
struct DeviceModel {
    double fixed_ms = 0.2;
    double per_node_ms = 3e-6;
    double noise = 0.0;  // relative, uniform in [-noise, noise]
    uint64_t state = 12345;
    double Time(uint64_t budget) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        const double u = double(state >> 11) / double(1ull << 53) * 2.0 - 1.0;
        return (fixed_ms + per_node_ms * double(budget)) * (1.0 + noise * u);
    }
};

// Runs `frames` frames, each frame's time observed `lag` frames later (frames in flight);
// returns each frame's time over the target.
std::vector<double> RunFrames(LodBudgetController& c, DeviceModel& device, double target,
                              int frames, uint64_t leaves, uint64_t cap = 0, int lag = 0) {
    std::deque<std::pair<uint64_t, double>> in_flight;
    std::vector<double> ratios;
    for (int f = 0; f < frames; ++f) {
        const uint64_t budget = c.NextBudget(target, leaves, cap);
        EXPECT_GE(budget, 1u);
        EXPECT_LE(budget, cap > 0 ? std::min(cap, leaves) : leaves);
        const double ms = device.Time(budget);
        ratios.push_back(ms / target);
        in_flight.push_back({budget, ms});
        if (int(in_flight.size()) > lag) {
            c.Observe(in_flight.front().first, in_flight.front().second);
            in_flight.pop_front();
        }
    }
    return ratios;
}

// Frames from `from` on within `tolerance` of the target.
int WithinFrom(const std::vector<double>& ratios, size_t from, double tolerance) {
    int n = 0;
    for (size_t i = from; i < ratios.size(); ++i) n += std::abs(ratios[i] - 1.0) <= tolerance;
    return n;
}

TEST(LodBudgetController, StartsAtTheCapOrAQuarterOfTheLeaves) {
    LodBudgetController c;
    // A quarter of 1M on the 1/32-octave grid: 2^(round(log2(250000) * 32) / 32).
    const uint64_t quarter = c.NextBudget(1.0, 1000000, 0);
    EXPECT_NEAR(double(quarter), 250000.0, 250000.0 * 0.011);
    EXPECT_EQ(LodBudgetController().NextBudget(1.0, 1000000, 5000), 5000u);
    EXPECT_EQ(LodBudgetController().NextBudget(1.0, 1000, 5000), 1000u) << "at most the leaves";
}

TEST(LodBudgetController, ReachesTheTargetAndHoldsIt) {
    // 1M leaves take 3.2 ms; 1.5 ms is held at (1.5 - 0.2) / 3e-6 = 433,333 nodes.
    LodBudgetController c;
    DeviceModel device;
    const std::vector<double> r = RunFrames(c, device, 1.5, 40, 1000000);
    // Within the dead band (3%) plus half a quantization step (1.1%) from frame 10 on.
    EXPECT_EQ(WithinFrom(r, 10, 0.045), 30);
    EXPECT_NEAR(double(c.LastBudget()), 433333.0, 433333.0 * 0.05);
}

TEST(LodBudgetController, HoldsTheTargetWithNoiseAndFramesInFlight) {
    // Each frame +-5% from the model, observed two frames late: 10% is the target.
    LodBudgetController c;
    DeviceModel device;
    device.noise = 0.05;
    const std::vector<double> r = RunFrames(c, device, 1.5, 200, 1000000, 0, 2);
    EXPECT_GE(WithinFrom(r, 20, 0.10), 178);  // at least 99% of the 180 frames
}

TEST(LodBudgetController, FollowsASceneWhoseCostChanges) {
    LodBudgetController c;
    DeviceModel device;
    RunFrames(c, device, 1.5, 30, 1000000);
    device.per_node_ms *= 2.0;  // the view turns to a denser part of the scene
    const std::vector<double> r = RunFrames(c, device, 1.5, 30, 1000000);
    EXPECT_GT(r[0], 1.5);  // the first frames miss
    EXPECT_EQ(WithinFrom(r, 10, 0.045), 20);
}

TEST(LodBudgetController, StaysWithinTheCapAndAboveOneNode) {
    LodBudgetController capped;
    DeviceModel device;
    RunFrames(capped, device, 1.5, 30, 1000000, 100000);
    EXPECT_EQ(capped.LastBudget(), 100000u) << "the target asks for more than the cap";
    LodBudgetController floor;
    RunFrames(floor, device, 0.1, 60, 1000000);  // below the fixed part: unreachable
    EXPECT_EQ(floor.LastBudget(), 1u);
    LodBudgetController all;
    RunFrames(all, device, 100.0, 30, 1000000);
    EXPECT_EQ(all.LastBudget(), 1000000u) << "every leaf is faster than the target";
}

TEST(LodBudgetController, GrowsFromAFewNodes) {
    // After an unreachable target the budget is 1; a target the frames then beat by 4% (past
    // the dead band, a step smaller than the grid's at such budgets) still makes it grow.
    LodBudgetController c;
    DeviceModel device;
    RunFrames(c, device, 0.1, 60, 1000000);
    ASSERT_EQ(c.LastBudget(), 1u);
    RunFrames(c, device, device.Time(1) * 1.04, 3, 1000000);
    EXPECT_GT(c.LastBudget(), 1u);
    // And a large target from there reaches its budget within ~25 frames of doubling.
    const std::vector<double> r = RunFrames(c, device, 1.5, 60, 1000000);
    EXPECT_EQ(WithinFrom(r, 40, 0.045), 20);
}

TEST(LodBudgetController, IgnoresFramesWithoutATime) {
    LodBudgetController c;
    const uint64_t first = c.NextBudget(1.0, 1000000, 0);
    c.Observe(first, 0.0);  // no timestamps (or a reused geometry stage)
    EXPECT_EQ(c.NextBudget(1.0, 1000000, 0), first);
    c.Observe(first, 4.0);  // 4x over: the step is at most a halving
    EXPECT_NEAR(double(c.NextBudget(1.0, 1000000, 0)), first / 2.0, first * 0.011);
}

TEST(LodBudgetController, ATargetThatIsNoFrameTimeIsRefused) {
    for (const double bad : {-1.0, std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity()}) {
        visualization::rendering::RenderConfig config;
        config.lod_target_ms = bad;
        EXPECT_THROW(config.Validate(), core::Open3DError);
    }
}

}  // namespace
}  // namespace tests
}  // namespace open3d
