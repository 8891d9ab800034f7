#include "GlGpuTimeline.h"

#include <fmt/format.h>

namespace gs_render {

namespace rendering = open3d::visualization::rendering;

GlGpuTimeline::GlGpuTimeline(const rendering::FilamentEngine& engine)
    : engine_(engine), queries_(std::make_shared<std::vector<std::array<uint32_t, kPoints>>>()) {}

GlGpuTimeline::~GlGpuTimeline() {
    const rendering::GlFunctions gl = engine_.GetGl();
    auto queries = queries_;
    engine_.RunOnDriverThread([gl, queries] {
        for (auto& frame : *queries) gl.DeleteQueries(kPoints, frame.data());
    });
    engine_.FlushAndWait();
}

void GlGpuTimeline::Mark(int frame, Point point) {
    const rendering::GlFunctions gl = engine_.GetGl();
    auto queries = queries_;
    engine_.RunOnDriverThread([gl, queries, frame, point] {
        while (int(queries->size()) <= frame) {
            std::array<uint32_t, kPoints> names{};
            gl.GenQueries(kPoints, names.data());
            queries->push_back(names);
        }
        gl.QueryCounter((*queries)[frame][point], GL_TIMESTAMP);
    });
    // Flushed at once, so that the timestamp is not taken late because Filament's stream
    // waited on the host for its next flush.
    engine_.Flush();
}

std::string GlGpuTimeline::Describe(int first) {
    if (!engine_.CanRunOnDriverThread()) {
        return "GL GPU timeline: none (" + engine_.DriverThreadUnavailableReason() + ")";
    }
    const rendering::GlFunctions gl = engine_.GetGl();
    auto queries = queries_;
    auto times = std::make_shared<std::vector<std::array<uint64_t, kPoints>>>();
    engine_.RunOnDriverThread([gl, queries, times] {
        times->assign(queries->size(), {});
        for (size_t f = 0; f < queries->size(); ++f) {
            for (int p = 0; p < kPoints; ++p) {
                GLuint64 ns = 0;
                gl.GetQueryObjectui64v((*queries)[f][p], GL_QUERY_RESULT, &ns);
                (*times)[f][p] = ns;
            }
        }
    });
    engine_.FlushAndWait();
    const std::vector<std::array<uint64_t, 3>>& t = *times;
    // Frames that have a next one: the last frame's "until the next frame" is unknown.
    double frame = 0, mesh = 0, splats = 0, next = 0;
    int n = 0;
    for (int f = first; f + 1 < int(t.size()); ++f, ++n) {
        frame += double(t[f + 1][kFrameBegin] - t[f][kFrameBegin]);
        mesh += double(t[f][kMeshDone] - t[f][kFrameBegin]);
        splats += double(t[f][kComposeDone] - t[f][kMeshDone]);
        next += double(t[f + 1][kFrameBegin] - t[f][kComposeDone]);
    }
    if (n == 0) return "GL GPU timeline: too few frames";
    const double ms = 1e-6 / n;
    return fmt::format(
        "GL GPU timeline (mean of {}): {:.3f} ms per frame = mesh view {:.3f} + until the "
        "compose view is done (GL waits for the splats, then draws) {:.3f} + until the next "
        "frame's first GL command runs {:.3f}",
        n, frame * ms, mesh * ms, splats * ms, next * ms);
}

}  // namespace gs_render
