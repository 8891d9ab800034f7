// gs-bench: the level-of-detail rows (--lod-budgets, --lod-cut-search).
#include "GsBenchRows.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>
#include "BenchScenes.h"
#include "LodBudgets.h"
#include "LodTarget.h"
#include "StreamBench.h"
#include "Throughput.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/core/Timer.h"
#include "open3d/t/geometry/ImageMetrics.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/OutputFiles.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamSession.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"

namespace open3d {
namespace bench {

namespace {

// --lod-cut-search's names.
const std::vector<std::pair<std::string, rendering::LodCutSearch>> kLodCutSearches = {
    {"auto", rendering::LodCutSearch::kAuto},
    {"every-node", rendering::LodCutSearch::kEveryNode},
    {"from-root", rendering::LodCutSearch::kFromRoot},
};

}  // namespace

std::vector<std::pair<std::string, rendering::LodCutSearch>> ParseLodCutSearches(
    const std::string& text) {
    std::vector<std::pair<std::string, rendering::LodCutSearch>> out;
    std::stringstream items(text);
    for (std::string item; std::getline(items, item, ',');) {
        const auto found = std::find_if(kLodCutSearches.begin(), kLodCutSearches.end(),
                                        [&](const auto& s) { return s.first == item; });
        if (found == kLodCutSearches.end()) {
            core::ThrowError("--lod-cut-search: '{}' is none of auto, every-node, from-root", item);
        }
        out.push_back(*found);
    }
    if (out.empty()) core::ThrowError("--lod-cut-search: give at least one search");
    return out;
}

// Level-of-detail rows (--lod-budgets), timed with the knobs before any CPU reference: per
// budget, every view's cut rendered and its colour compared with the exact render of the
// whole scene. With Vulkan the scene is the hierarchy's nodes and the cut is chosen on the
// GPU each frame (RenderConfig::lod_budget: its passes are in the projection's time); other
// backends render the CPU cut (CutSplatHierarchy) set as their scene.
void AddLodRows(const Options& opt, const std::vector<int64_t>& budgets, const SceneJob& job,
                const t::geometry::SplatHierarchy& hierarchy, double hierarchy_ms,
                rendering::GaussianSplatBackend& backend,
                const std::vector<camera::PinholeCamera>& cams, const std::string& resolution,
                std::vector<Row>& rows) {
    // The default knob: exact order, float32 storage.
    rendering::RenderConfig config = TimedConfig(opt);
    std::vector<t::geometry::Image> exact, filtered;
    // --lod-supersample: the exact render against the filtered one, worst view (every row's).
    double exact_filtered_psnr = std::numeric_limits<double>::infinity();
    for (const auto& cam : cams) {
        exact.push_back(backend.Render(cam, config).color);
        if (opt.lod_supersample > 0) {
            filtered.push_back(bench::FilteredReference(backend, cam, opt.lod_supersample, config));
            exact_filtered_psnr = std::min(
                exact_filtered_psnr, t::geometry::ComputePSNR(exact.back(), filtered.back(), 1.0));
        }
    }
    // The hierarchy's backend is another device context: the exact scene's buffers go first
    // (the 98M-splat grid held both and failed on an 80 GB card), and come back after it is
    // gone (declared first, so destroyed last).
    struct RestoreScene {
        rendering::GaussianSplatBackend& backend;
        const t::geometry::PointCloud& cloud;
        bool released = false;
        ~RestoreScene() {
            if (released) backend.SetScene(cloud);
        }
    } restore{backend, job.cloud};
    // Freed before the new context is made: it takes its room from the device's memory
    // budget less what the process uses at that moment.
    if (dynamic_cast<rendering::vulkan::GaussianSplatVulkanBackend*>(&backend) != nullptr) {
        backend.ReleaseResources();
        restore.released = true;
    }
    auto lod_backend = rendering::CreateGaussianSplatBackend(opt.backend);
    auto* vulkan = dynamic_cast<rendering::vulkan::GaussianSplatVulkanBackend*>(lod_backend.get());
    if (vulkan != nullptr) {
        vulkan->SetFramesInFlight(opt.frames_in_flight);
        vulkan->CheckHierarchyFits(job.cloud.NumPoints(),
                                   job.cloud.GetGaussianSplatArrays().sh_degree);
        vulkan->SetSceneHierarchy(job.cloud, hierarchy);
    }
    const double n = static_cast<double>(cams.size());
    const auto searches = ParseLodCutSearches(opt.lod_cut_search);
    // A row per budget and search, budgets first.
    struct LodRow {
        int64_t budget;
        std::string search_name;
        rendering::LodCutSearch search;
    };
    std::vector<LodRow> lod_rows;
    for (const int64_t budget : budgets) {
        for (const auto& [name, search] : searches) lod_rows.push_back({budget, name, search});
    }
    for (const auto& [budget, search_name, search] : lod_rows) {
        Row row;
        row.scene = job.name;
        row.resolution = resolution;
        row.knob = "lod " + bench::BudgetLabel(budget);
        if (searches.size() > 1) row.knob += " " + search_name;
        config.lod_cut_search = search;
        row.splats = job.cloud.NumPoints();
        row.lod_budget = budget;
        row.lod_on_gpu = vulkan != nullptr;
        row.hierarchy_build_ms = hierarchy_ms;
        if (opt.lod_supersample > 0) {
            row.lod_supersample = opt.lod_supersample;
            row.exact_filtered_psnr = exact_filtered_psnr;
            row.lod_filtered_psnr = std::numeric_limits<double>::infinity();
        }
        config.lod_budget = static_cast<uint64_t>(budget);
        for (size_t v = 0; v < cams.size(); ++v) {
            double scene_nodes = static_cast<double>(hierarchy.NumNodes());
            if (vulkan == nullptr) {
                const bench::LodCut cut = bench::CutForView(hierarchy, job.cloud, cams[v], budget);
                row.lod_nodes += static_cast<double>(cut.nodes) / n;
                row.lod_cut_ms += cut.cut_ms / n;
                lod_backend->SetScene(cut.cloud);
                scene_nodes = static_cast<double>(cut.nodes);
            }
            const rendering::RenderOutput out = lod_backend->Render(cams[v], config);
            if (vulkan != nullptr)
                row.lod_nodes += static_cast<double>(out.stats.lod_cut_nodes) / n;
            const TimedFrames timed = RunTimedFrames(*lod_backend, cams[v], config, opt.repeat,
                                                     opt.depth, opt.warm_up_seconds);
            AddView(row, timed, out.stats, cams.size());
            row.bytes_per_splat += static_cast<double>(out.stats.gpu_scene_bytes) / scene_nodes / n;
            if (vulkan != nullptr) {
                const auto [in_flight, with_readback] =
                    PipelinedMs(opt, *vulkan, {cams[v]}, config);
                row.pipelined_ms += in_flight / n;
                row.pipelined_readback_ms += with_readback / n;
            }
            AddViewError(row, out.color, exact[v]);
            if (opt.lod_supersample > 0) {
                row.lod_filtered_psnr = std::min(
                    row.lod_filtered_psnr, t::geometry::ComputePSNR(out.color, filtered[v], 1.0));
            }
            if (vulkan != nullptr && v == 0) {
                const rendering::RenderStats after = lod_backend->Render(cams[v], config).stats;
                row.lod_walk_visited = after.lod_walk_visited;
                row.lod_walks = after.lod_walks;
            }
        }
        row.gpu_total_ms = row.project_ms + row.sort_ms + row.composite_ms;
        rows.push_back(row);
    }
    if (opt.lod_target_ms > 0.0) {
        if (vulkan == nullptr)
            core::ThrowError("--lod-target-ms: the backend times frames on the GPU: use vulkan");
        rendering::RenderConfig target = TimedConfig(opt);
        target.lod_target_ms = opt.lod_target_ms;
        const LodTargetResult result =
            RunLodTargetPath(*lod_backend, cams, target, opt.lod_target_frames, 30);
        PrintLodTargetResult(job.name.c_str(), cams.at(0).width, cams.at(0).height, result);
    }
}

}  // namespace bench
}  // namespace open3d
