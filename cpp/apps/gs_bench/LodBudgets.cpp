#include "LodBudgets.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>

#include "BenchScenes.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Timer.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamer.h"

namespace open3d {
namespace bench {

std::vector<int64_t> ParseBudgets(const std::string& text) {
    std::vector<int64_t> budgets;
    size_t start = 0;
    while (start <= text.size()) {
        const size_t comma = text.find(',', start);
        const std::string item = text.substr(start, comma - start);
        char* end = nullptr;
        const double value = item.empty() ? NAN : std::strtod(item.c_str(), &end);
        double scale = 1.0;
        if (end != nullptr && (*end == 'k' || *end == 'M')) {
            scale = *end == 'k' ? 1e3 : 1e6;
            ++end;
        }
        const double splats = value * scale;
        if (end == nullptr || *end != '\0' || !(splats >= 1.0) || splats > 1e12 ||
            splats != std::floor(splats)) {
            core::ThrowError(
                "--lod-budgets: '{}' is not a splat count (a whole number >= 1, k = 1000 and "
                "M = 1000000 allowed, e.g. 500k,1M,2.5M)",
                item);
        }
        budgets.push_back(static_cast<int64_t>(splats));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return budgets;
}

std::string BudgetLabel(int64_t budget) {
    const auto shortest = [](double v) {
        std::string s = fmt::format("{:.3f}", v);
        s.erase(s.find_last_not_of('0') + 1);
        if (s.back() == '.') s.pop_back();
        return s;
    };
    if (budget >= 1000000 && budget % 1000 == 0) return shortest(budget / 1e6) + "M";
    if (budget >= 1000 && budget % 10 == 0) return shortest(budget / 1e3) + "k";
    return std::to_string(budget);
}

t::geometry::Image FilteredReference(visualization::rendering::GaussianSplatBackend& backend,
                                     const camera::PinholeCamera& camera, int s,
                                     const visualization::rendering::RenderConfig& config) {
    const int w = camera.width, h = camera.height;
    if (s < 1 || w % s != 0 || h % s != 0) {
        core::ThrowError("--lod-supersample {}: does not divide the view's {} x {} pixels", s, w,
                         h);
    }
    const camera::PinholeCamera fine = SupersampledView(camera, s);
    t::geometry::Image out;
    for (int ty = 0; ty < s; ++ty) {
        for (int tx = 0; tx < s; ++tx) {
            // Fine pixels [tx w, (tx + 1) w) x [ty h, (ty + 1) h) of the s-times image.
            camera::PinholeCamera tile = fine;
            tile.width = w;
            tile.height = h;
            tile.cx = fine.cx - double(tx) * w;
            tile.cy = fine.cy - double(ty) * h;
            const visualization::rendering::RenderOutput frame = backend.Render(tile, config);
            if (frame.stats.error_flags != 0) {
                core::ThrowError(
                    "--lod-supersample {}: tile ({}, {}) of the filtered reference dropped tile "
                    "entries (error flags {}): raise --max-tile-entries",
                    s, tx, ty, frame.stats.error_flags);
            }
            const t::geometry::Image block = frame.color.BoxDownsample(s);
            if (out.IsEmpty()) {
                out = t::geometry::Image(h, w, block.GetChannels(), core::Dtype::Float32);
            }
            const int64_t c = block.GetChannels();
            for (int64_t y = 0; y < block.GetRows(); ++y) {
                std::copy_n(block.Data<float>() + y * block.GetCols() * c, block.GetCols() * c,
                            &out.At<float>(ty * (h / s) + y, tx * (w / s)));
            }
        }
    }
    return out;
}

LodCut CutForView(const t::geometry::SplatHierarchy& hierarchy,
                  const t::geometry::PointCloud& source, const camera::PinholeCamera& camera,
                  int64_t budget) {
    const auto start = std::chrono::steady_clock::now();
    const std::vector<int64_t> nodes = t::geometry::CutSplatHierarchy(
        hierarchy, visualization::rendering::SplatCutViewOf(camera), budget);
    LodCut cut;
    cut.cloud = t::geometry::ExtractSplatNodes(hierarchy, source, nodes);
    cut.nodes = static_cast<int64_t>(nodes.size());
    cut.cut_ms = core::MillisecondsSince(start);
    return cut;
}

}  // namespace bench
}  // namespace open3d
