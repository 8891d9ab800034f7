// Streaming a paged splat file through a pool of page slots (SplatStreamer): with room for
// what the view needs the cut converges to every leaf the view can see (counted here
// independently from the source splats), pages the view stops using are evicted for the
// ones it asks for and read again when it returns, the cut stays within its budget, and a
// pool too small for the view says so.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/SplatPageFile.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamSession.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamWorker.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamer.h"
#include "t/io/RandomSplatCloud.h"

namespace open3d {
namespace tests {
namespace {

using t::geometry::PointCloud;
using visualization::rendering::SplatCutViewOf;
using visualization::rendering::SplatStreamer;
using visualization::rendering::SplatStreamStep;
using visualization::rendering::SplatStreamWorker;
namespace rendering = visualization::rendering;

// Two clusters of `n` splats each, 1000 units apart on x, 20 units in front of cameras at
// x = 0 and x = 1000 that look down +z: each camera sees one cluster only.
PointCloud TwoClusters(int64_t n) {
    PointCloud cloud = t::io::RandomCloud(2 * n, 1, 11);
    float* p = cloud.GetPointAttr("positions").Data<float>();
    float* s = cloud.GetPointAttr("scale").Data<float>();
    for (int64_t i = 0; i < 2 * n; ++i) {
        p[3 * i + 0] = 0.2f * p[3 * i + 0] + (i < n ? 0.0f : 1000.0f);
        p[3 * i + 1] = 0.2f * p[3 * i + 1];
        p[3 * i + 2] = 0.1f * p[3 * i + 2] + 20.0f;
        for (int axis = 0; axis < 3; ++axis) s[3 * i + axis] = std::min(s[3 * i + axis], 0.3f);
    }
    return cloud;
}

camera::PinholeCamera CameraAt(double x) {
    camera::PinholeCamera cam;
    cam.width = cam.height = 64;
    cam.fx = cam.fy = 60.0;
    cam.cx = cam.cy = 31.5;
    cam.world_to_camera(0, 3) = -x;
    return cam;
}

// The leaves a camera can see: those whose 3-sigma sphere is not outside its view.
std::set<int64_t> LeavesInView(const PointCloud& cloud, const camera::PinholeCamera& cam) {
    const t::geometry::SplatCutView view = SplatCutViewOf(cam);
    const float* p = cloud.GetPointAttr("positions").Data<float>();
    const float* s = cloud.GetPointAttr("scale").Data<float>();
    std::set<int64_t> in_view;
    for (int64_t i = 0; i < cloud.NumPoints(); ++i) {
        const Eigen::Vector3d c =
            (cam.world_to_camera * Eigen::Vector4d(p[3 * i], p[3 * i + 1], p[3 * i + 2], 1.0))
                .head<3>();
        const double radius = 3.0 * std::max({s[3 * i], s[3 * i + 1], s[3 * i + 2]});
        if (!t::geometry::SplatOutsideView(view, c, radius)) in_view.insert(i);
    }
    return in_view;
}

// The hierarchy ids of the nodes a mask shows, the pool's slots holding `slot_pages`.
std::set<int64_t> Drawn(const t::io::SplatPageFile& file, const std::vector<int64_t>& slot_pages,
                        const std::vector<uint32_t>& mask) {
    std::set<int64_t> drawn;
    for (int64_t s = 0; s < int64_t(slot_pages.size()) * file.PageCapacity(); ++s) {
        if (!(mask[s / 32] >> (s % 32) & 1u)) continue;
        const int64_t page = slot_pages.at(s / file.PageCapacity());
        EXPECT_GE(page, 0) << "slot " << s << " is shown but empty";
        if (page < 0) continue;
        drawn.insert(file.ReadNodes(page).at(s % file.PageCapacity()).source_id);
    }
    return drawn;
}
std::set<int64_t> Drawn(const t::io::SplatPageFile& file, const SplatStreamer& streamer,
                        const SplatStreamStep& step) {
    return Drawn(file, streamer.SlotPages(), step.visibility);
}

// Steps until nothing the view wants is missing; returns the last step.
SplatStreamStep Converge(SplatStreamer& streamer, const camera::PinholeCamera& cam) {
    SplatStreamStep step;
    for (int i = 0; i < 1000; ++i) {
        step = streamer.Step(SplatCutViewOf(cam), 2);
        if (step.pages_wanted == 0) return step;
    }
    ADD_FAILURE() << "did not converge";
    return step;
}

struct Paged {
    PointCloud cloud;
    std::string path;
};
Paged WritePaged(int64_t n, int64_t capacity) {
    Paged paged{TwoClusters(n), TempDir() + "/two_clusters.gspages"};
    t::io::WriteSplatPages(paged.path, paged.cloud, t::geometry::BuildSplatHierarchy(paged.cloud),
                           capacity);
    return paged;
}

TEST(SplatStreamer, ConvergesToEveryLeafInView) {
    const Paged paged = WritePaged(300, 16);
    const t::io::SplatPageFile file(paged.path);
    const camera::PinholeCamera cam = CameraAt(0.0);
    const std::set<int64_t> expected = LeavesInView(paged.cloud, cam);
    ASSERT_GT(expected.size(), 200u);
    ASSERT_LT(expected.size(), 320u);  // the other cluster is not in view
    SplatStreamer streamer(file, file.NumPages(), file.NumLeaves());
    // The first step reads the root's page alone and already draws something.
    const SplatStreamStep first = streamer.Step(SplatCutViewOf(cam), 0);
    EXPECT_EQ(first.writes.size(), 1u);
    EXPECT_GE(first.cut_nodes, 1);
    EXPECT_GT(first.pages_wanted, 0);
    const SplatStreamStep last = Converge(streamer, cam);
    EXPECT_FALSE(last.starved);
    EXPECT_EQ(Drawn(file, streamer, last), expected);
    EXPECT_EQ(last.cut_nodes, int64_t(expected.size()));
    // Only what the view opened into was read.
    EXPECT_LT(streamer.ResidentPages(), file.NumPages());
}

TEST(SplatStreamer, EvictsWhatTheViewLeftAndReadsItAgain) {
    const Paged paged = WritePaged(300, 16);
    const t::io::SplatPageFile file(paged.path);
    const camera::PinholeCamera a = CameraAt(0.0), b = CameraAt(1000.0);
    int64_t need_a = 0, need_b = 0;
    for (const auto& [cam, need] : {std::pair{a, &need_a}, std::pair{b, &need_b}}) {
        SplatStreamer unlimited(file, file.NumPages(), file.NumLeaves());
        Converge(unlimited, cam);
        *need = unlimited.ResidentPages();
    }
    // Room for either view, not for both (they share the root's page and little more).
    const int64_t pool = std::max(need_a, need_b);
    ASSERT_LT(pool, need_a + need_b - 2);
    SplatStreamer streamer(file, pool, file.NumLeaves());
    for (const camera::PinholeCamera& cam : {a, b, a}) {
        const SplatStreamStep last = Converge(streamer, cam);
        EXPECT_EQ(Drawn(file, streamer, last), LeavesInView(paged.cloud, cam));
    }
    EXPECT_GT(streamer.Evictions(), 0);
    EXPECT_GT(streamer.PagesRead(), need_a + need_b);  // a's pages were read twice
}

TEST(SplatStreamer, AStepForTheSameViewCutsAsACutFromTheRoot) {
    // A step for the view of the step before only opens the nodes that waited for the pages
    // read since. A second streamer whose view differs in the last bit of the focal length
    // every other step (sizes scale alike, so it reads the same pages in the same order)
    // cuts from the root each time: the two must draw the same nodes from the same slots.
    const Paged paged = WritePaged(300, 16);
    const t::io::SplatPageFile file(paged.path);
    const t::geometry::SplatCutView view = SplatCutViewOf(CameraAt(0.0));
    t::geometry::SplatCutView nudged = view;
    nudged.focal_px = std::nextafter(view.focal_px, 1e9);
    SplatStreamer incremental(file, file.NumPages(), file.NumLeaves());
    SplatStreamer from_root(file, file.NumPages(), file.NumLeaves());
    int steps = 0;
    for (; steps < 200; ++steps) {
        const SplatStreamStep a = incremental.Step(view, 1);
        const SplatStreamStep b = from_root.Step(steps % 2 ? view : nudged, 1);
        ASSERT_EQ(a.visibility, b.visibility) << "step " << steps;
        ASSERT_EQ(incremental.SlotPages(), from_root.SlotPages()) << "step " << steps;
        EXPECT_EQ(a.cut_nodes, b.cut_nodes);
        EXPECT_EQ(a.pages_wanted, b.pages_wanted);
        if (a.pages_wanted == 0) break;
    }
    EXPECT_GT(steps, 10);  // many steps extended the cut
}

TEST(SplatStreamer, TheCutStaysWithinItsBudget) {
    const Paged paged = WritePaged(300, 16);
    const t::io::SplatPageFile file(paged.path);
    const camera::PinholeCamera cam = CameraAt(0.0);
    for (const int64_t budget : {int64_t(1), int64_t(7), int64_t(40), int64_t(150)}) {
        SplatStreamer streamer(file, file.NumPages(), budget);
        SplatStreamStep step;
        for (int i = 0; i < 200; ++i) {
            step = streamer.Step(SplatCutViewOf(cam), 1);
            ASSERT_LE(step.cut_nodes, budget);
            ASSERT_EQ(Drawn(file, streamer, step).size(), size_t(step.cut_nodes));
            if (step.pages_wanted == 0) break;
        }
        EXPECT_EQ(step.pages_wanted, 0);
        // A cut that fills less than its budget less the largest group (8) could open more.
        if (budget >= 40) {
            EXPECT_GT(step.cut_nodes, budget - 8);
        }
    }
    EXPECT_THROW(SplatStreamer(file, 4, 0), core::Open3DError);
    EXPECT_THROW(SplatStreamer(file, 0, 10), core::Open3DError);
}

TEST(SplatStreamer, APoolTooSmallForTheViewSaysSo) {
    const Paged paged = WritePaged(300, 16);
    const t::io::SplatPageFile file(paged.path);
    SplatStreamer streamer(file, 1, file.NumLeaves());
    const camera::PinholeCamera cam = CameraAt(0.0);
    streamer.Step(SplatCutViewOf(cam), 4);
    const SplatStreamStep second = streamer.Step(SplatCutViewOf(cam), 4);
    EXPECT_TRUE(second.starved);
    EXPECT_GT(second.pages_wanted, 0);
    EXPECT_EQ(streamer.SlotPages(), std::vector<int64_t>{0});  // the root's page stays
    EXPECT_GE(Drawn(file, streamer, second).size(), 1u);
}

TEST(SplatStreamer, AFullPoolKeepsWhatTheCutUsesInsteadOfThrashing) {
    // One slot short of what the view needs: once the pool is full of pages the cut uses, a
    // step must read nothing (evicting a used page would coarsen the picture, ask for the page
    // again and read pages every step without end).
    const Paged paged = WritePaged(300, 16);
    const t::io::SplatPageFile file(paged.path);
    const camera::PinholeCamera cam = CameraAt(0.0);
    int64_t need = 0;
    {
        SplatStreamer unlimited(file, file.NumPages(), file.NumLeaves());
        Converge(unlimited, cam);
        need = unlimited.ResidentPages();
    }
    ASSERT_GT(need, 3);
    SplatStreamer streamer(file, need - 1, file.NumLeaves());
    SplatStreamStep step;
    for (int i = 0; i < 100 && !step.starved; ++i) step = streamer.Step(SplatCutViewOf(cam), 1);
    ASSERT_TRUE(step.starved);
    const int64_t read = streamer.PagesRead();
    const std::set<int64_t> drawn = Drawn(file, streamer, step);
    for (int i = 0; i < 5; ++i) {
        step = streamer.Step(SplatCutViewOf(cam), 1);
        EXPECT_TRUE(step.starved);
        EXPECT_GT(step.pages_wanted, 0);
    }
    EXPECT_EQ(streamer.PagesRead(), read);
    EXPECT_EQ(Drawn(file, streamer, step), drawn);
}

TEST(SplatStreamWorker, ConvergesOffTheCallersThreadAsTheViewMoves) {
    // The worker steps on its own thread; this thread takes what changed now and then (as a
    // render loop would), applies the page writes to its own record of the slots, and must
    // end with every leaf in view drawn, for each view in turn, in a pool too small for both.
    const Paged paged = WritePaged(300, 16);
    const t::io::SplatPageFile file(paged.path);
    const camera::PinholeCamera a = CameraAt(0.0), b = CameraAt(1000.0);
    int64_t need = 0;
    for (const camera::PinholeCamera& cam : {a, b}) {
        SplatStreamer unlimited(file, file.NumPages(), file.NumLeaves());
        Converge(unlimited, cam);
        need = std::max(need, unlimited.ResidentPages());
    }
    SplatStreamer streamer(file, need, file.NumLeaves());
    std::vector<int64_t> slot_pages(need, -1);
    std::vector<uint32_t> mask((streamer.PoolSplats() + 31) / 32, 0u);
    int64_t takes = 0;
    const auto take = [&](SplatStreamWorker& worker) {
        if (std::optional<SplatStreamStep> step = worker.Take()) {
            for (const SplatStreamStep::PageWrite& write : step->writes) {
                slot_pages.at(write.first_splat / file.PageCapacity()) = write.page;
            }
            mask = step->visibility;
            ++takes;
        }
    };
    {
        SplatStreamWorker worker(streamer, 1);
        for (const camera::PinholeCamera& cam : {a, b, a}) {
            worker.SetView(SplatCutViewOf(cam));
            for (int i = 0; i < 20000 && !worker.Idle(); ++i) {
                take(worker);
                std::this_thread::sleep_for(std::chrono::microseconds(200));
            }
            ASSERT_TRUE(worker.Idle());
            take(worker);  // the last step's changes
            EXPECT_EQ(Drawn(file, slot_pages, mask), LeavesInView(paged.cloud, cam));
        }
        worker.SetView(SplatCutViewOf(b));  // destroyed while it works: joins, no hang
    }
    // At least one take per view; how many steps each view's convergence is split into
    // depends on how fast the worker runs against this thread (an idle machine converges
    // each view before the first take), so no more is asked.
    EXPECT_GE(takes, 3);
    EXPECT_GT(streamer.Evictions(), 0);
    EXPECT_THROW(SplatStreamWorker(streamer, 0), core::Open3DError);
}

TEST(SplatStreamSession, ByteSizesAndPoolPages) {
    using rendering::ParseByteSize;
    EXPECT_EQ(ParseByteSize("2G"), uint64_t(2) << 30);
    EXPECT_EQ(ParseByteSize("1.5K"), 1536u);
    EXPECT_EQ(ParseByteSize("123456"), 123456u);
    // "0.5" would round to 0 bytes, which callers read as the default: refused.
    for (const char* bad : {"", "lots", "2X", "-1", "0", "0.5", "1e30T"}) {
        EXPECT_THROW(ParseByteSize(bad), core::Open3DError) << bad;
    }
    EXPECT_EQ(rendering::ParseGpuBudget("auto"), 0u);  // the default pool
    EXPECT_EQ(rendering::ParseGpuBudget("512M"), uint64_t(512) << 20);
    EXPECT_THROW(rendering::ParseGpuBudget("0"), core::Open3DError);
    const Paged paged = WritePaged(500, 64);
    const t::io::SplatPageFile file(paged.path);
    ASSERT_GT(file.NumPages(), 5);
    const double page_bytes = rendering::StreamPoolBytesPerSplat(file.ShDegree()) * 64.0;
    using rendering::StreamPoolPages;
    // As many whole pages as the budget holds, never more than the file has.
    EXPECT_EQ(StreamPoolPages(file, uint64_t(3.5 * page_bytes)), 3);
    EXPECT_EQ(StreamPoolPages(file, uint64_t(1) << 40), file.NumPages());
    EXPECT_EQ(StreamPoolPages(file, 0), file.NumPages());  // the default, 1 GiB
    // A device that holds 197 splats in a scene: the default takes its 3 pages, a budget
    // above it is refused, one above the file's size asks for no more than the file.
    EXPECT_EQ(StreamPoolPages(file, 0, 197), 3);
    ExpectErrorContaining([&] { StreamPoolPages(file, uint64_t(5 * page_bytes), 197); },
                          "this device holds at most 197 splats");
    EXPECT_EQ(StreamPoolPages(file, uint64_t(1) << 40, 64 * file.NumPages()), file.NumPages());
    ExpectErrorContaining([&] { StreamPoolPages(file, uint64_t(0.5 * page_bytes)); },
                          "holds no page");
    ExpectErrorContaining([&] { StreamPoolPages(file, 0, 63); }, "not one page of 64");
    // At half precision a splat of degree 1 takes 16 + 4 x 5 + 4 x 5 bytes (9 SH values in
    // fp16 pairs) and its bit, against 16 + 4 x 10 + 4 x 9: the budget of 3.5 exact pages
    // holds 3.5 x 92.125 / 56.125 = 5.7 compact ones.
    ASSERT_EQ(file.ShDegree(), 1);
    EXPECT_EQ(rendering::StreamPoolBytesPerSplat(1), 92.125);
    EXPECT_EQ(rendering::StreamPoolBytesPerSplat(1, true), 56.125);
    EXPECT_EQ(StreamPoolPages(file, uint64_t(3.5 * page_bytes), INT64_MAX, true), 5);
}

TEST(SplatStreamSession, APageRefusedMidStreamSettlesWithItsError) {
    const Paged paged = WritePaged(500, 64);
    {
        // Every page but the root's ends in a NaN: the header and the page table stay valid,
        // the second page read is refused.
        std::vector<uint8_t> bytes = ReadFileBytes(paged.path);
        const t::io::SplatPageFile file(paged.path);
        for (int64_t p = 1; p < file.NumPages(); ++p) {
            const uint64_t end = file.Page(p).offset + file.PageBytes(p);
            std::fill(bytes.begin() + end - 4, bytes.begin() + end, uint8_t(0xFF));
        }
        WriteFileBytes(paged.path, bytes);
    }
    rendering::SplatStreamSession session(paged.path, {});
    EXPECT_FALSE(session.Progress().settled);  // no view yet
    session.SetView(CameraAt(0.0));
    const auto start = std::chrono::steady_clock::now();
    while (!session.Progress().settled &&
           std::chrono::steady_clock::now() - start < std::chrono::seconds(20)) {
        session.Take();
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    rendering::SplatStreamProgress p = session.Progress();
    ASSERT_TRUE(p.settled);
    EXPECT_NE(p.error.find(paged.path), std::string::npos) << p.error;
    EXPECT_NE(rendering::FormatStreamProgress(p).find("; stopped: "), std::string::npos);
    EXPECT_EQ(p.resident_pages, 1);  // the root's page, read before the refusal
    // The worker steps no more: a new view does not unsettle it.
    session.SetView(CameraAt(1000.0));
    EXPECT_TRUE(session.Progress().settled);
    EXPECT_FALSE(session.HasNews());
}

}  // namespace
}  // namespace tests
}  // namespace open3d
