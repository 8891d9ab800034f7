#include "LodBudgets.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>

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
