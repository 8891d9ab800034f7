#include "open3d/visualization/rendering/gaussian_splat/SplatStreamer.h"

#include <algorithm>
#include <chrono>
#include <queue>

#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/core/Timer.h"

namespace open3d {
namespace visualization {
namespace rendering {

t::geometry::SplatCutView SplatCutViewOf(const camera::PinholeCamera& camera) {
    t::geometry::SplatCutView view;
    view.world_to_camera = camera.world_to_camera;
    view.focal_px = std::max(camera.fx, camera.fy);
    view.width = camera.width;
    view.height = camera.height;
    view.fx = camera.fx;
    view.fy = camera.fy;
    view.cx = camera.cx;
    view.cy = camera.cy;
    return view;
}

SplatStreamer::SplatStreamer(const t::io::SplatPageFile& file, int64_t pool_pages,
                             int64_t splat_budget)
    : file_(file), pool_pages_(pool_pages), budget_(splat_budget) {
    if (pool_pages < 1) {
        core::ThrowError("SplatStreamer: the pool needs at least one page slot, not {}",
                         pool_pages);
    }
    if (splat_budget < 1) {
        core::ThrowError("SplatStreamer: the splat budget must be >= 1, not {}", splat_budget);
    }
    records_.resize(file.NumPages());
    waiting_.resize(file.NumPages());
    waiting_size_.assign(file.NumPages(), -1.0);
    page_used_.assign(file.NumPages(), 0);
    page_slot_.assign(file.NumPages(), -1);
    slot_page_.assign(pool_pages, -1);
    last_used_.assign(file.NumPages(), 0);
}

int64_t SplatStreamer::ResidentPages() const {
    return std::count_if(slot_page_.begin(), slot_page_.end(), [](int64_t p) { return p >= 0; });
}

namespace {

// Whether `node` is in `view`; if so, its projected size (focal x radius / depth, a node
// nearer than its size counted large), as CutSplatHierarchy measures it.
bool InView(const t::geometry::SplatCutView& view, const t::io::SplatPageNode& node, double& size) {
    const Eigen::Vector3d p(node.position[0], node.position[1], node.position[2]);
    const Eigen::Vector3d c = view.world_to_camera.topLeftCorner<3, 3>() * p +
                              view.world_to_camera.topRightCorner<3, 1>();
    if (t::geometry::SplatOutsideView(view, c, node.bound_radius)) return false;
    const double radius = node.radius;
    size = view.focal_px * radius / std::max(c.z(), 1e-3 * radius + 1e-30);
    return true;
}

bool SameView(const t::geometry::SplatCutView& a, const t::geometry::SplatCutView& b) {
    return a.world_to_camera == b.world_to_camera && a.focal_px == b.focal_px &&
           a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
           a.cx == b.cx && a.cy == b.cy;
}

}  // namespace

void SplatStreamer::ClearCut() {
    drawn_.clear();
    for (int64_t page : waiting_pages_) {
        waiting_[page].clear();
        waiting_size_[page] = -1.0;
    }
    waiting_pages_.clear();
    for (int64_t page : used_pages_) page_used_[page] = 0;
    used_pages_.clear();
    UsePage(0);
}

void SplatStreamer::UsePage(int64_t page) {
    if (page_used_[page]) return;
    page_used_[page] = 1;
    used_pages_.push_back(page);
}

int64_t SplatStreamer::ChildrenPageOrWait(const Open& open) {
    const int64_t page = file_.PageOfNode(Node(open.id, open.page).first_child);
    if (page_slot_[page] >= 0) return page;
    drawn_.push_back({open.id, open.page});
    if (waiting_[page].empty()) waiting_pages_.push_back(page);
    waiting_[page].push_back(static_cast<int64_t>(drawn_.size()) - 1);
    waiting_size_[page] = std::max(waiting_size_[page], open.size);
    return -1;
}

void SplatStreamer::OrderedCut(const t::geometry::SplatCutView& view) {
    // The greedy cut of CutSplatHierarchy (largest projected size opens first, a node whose
    // children do not fit the budget stays whole) over the pages in the pool: a node whose
    // children's page is not there stays whole too, and waits for that page.
    ClearCut();
    have_cut_ = false;
    arrived_.clear();
    std::priority_queue<Open> open;
    int64_t count = 0;  // nodes drawn and open
    const auto add = [&](int64_t id, int64_t page, double size) {
        ++count;
        if (Node(id, page).num_children == 0) {
            drawn_.push_back({id, page});
        } else {
            open.push({size, id, page});
        }
    };
    if (double size; InView(view, Node(0, 0), size)) add(0, 0, size);
    while (!open.empty()) {
        const Open top = open.top();
        open.pop();
        const int64_t page = ChildrenPageOrWait(top);
        if (page < 0) continue;
        const t::io::SplatPageNode& node = Node(top.id, top.page);
        // Children outside the view are dropped, so opening adds the visible ones less one.
        double sizes[8];
        bool visible[8];
        int64_t num_visible = 0;
        for (uint32_t i = 0; i < node.num_children; ++i) {
            visible[i] = InView(view, Node(node.first_child + i, page), sizes[i]);
            num_visible += visible[i];
        }
        if (count - 1 + num_visible > budget_) {
            drawn_.push_back({top.id, top.page});
            continue;
        }
        UsePage(page);
        --count;
        for (uint32_t i = 0; i < node.num_children; ++i) {
            if (visible[i]) add(node.first_child + i, page, sizes[i]);
        }
    }
}

void SplatStreamer::Expand(const t::geometry::SplatCutView& view, std::vector<Open>& stack) {
    while (!stack.empty()) {
        const Open top = stack.back();
        stack.pop_back();
        const int64_t page = ChildrenPageOrWait(top);
        if (page < 0) continue;
        const t::io::SplatPageNode& node = Node(top.id, top.page);
        UsePage(page);
        for (uint32_t i = 0; i < node.num_children; ++i) {
            const int64_t child = node.first_child + i;
            double size;
            if (!InView(view, Node(child, page), size)) continue;  // nothing below it is seen
            if (Node(child, page).num_children == 0) {
                drawn_.push_back({child, page});
            } else {
                stack.push_back({size, child, page});
            }
        }
    }
}

void SplatStreamer::UnorderedCut(const t::geometry::SplatCutView& view) {
    // A budget that cannot bind leaves the order in which nodes open free, and a step for the same
    // view as the last one only opens the nodes that waited for the pages read since: the cut's
    // cost follows what arrived, not the cut's size (8M nodes took 4 s to cut again from the root).
    std::vector<Open> stack;
    if (!have_cut_ || !SameView(view, cut_view_)) {
        ClearCut();
        if (double size; InView(view, Node(0, 0), size)) {
            if (Node(0, 0).num_children == 0) {
                drawn_.push_back({0, 0});
            } else {
                stack.push_back({size, 0, 0});
            }
        }
        have_cut_ = true;
        cut_view_ = view;
    } else {
        for (int64_t page : arrived_) {
            if (page_slot_[page] < 0) continue;  // read, then evicted unused
            for (int64_t index : waiting_[page]) {
                auto& [id, node_page] = drawn_[index];
                if (id < 0) continue;
                stack.push_back({waiting_size_[page], id, node_page});
                id = -1;
            }
            waiting_[page].clear();
            waiting_size_[page] = -1.0;
        }
    }
    arrived_.clear();
    Expand(view, stack);
}

bool SplatStreamer::Load(int64_t page, SplatStreamStep& step) {
    int64_t slot = -1;
    for (int64_t s = 0; s < pool_pages_ && slot < 0; ++s) {
        if (slot_page_[s] < 0) slot = s;
    }
    if (slot < 0) {
        // The least recently used page that this step's cut does not use (never the root's).
        uint64_t oldest = step_;
        for (int64_t s = 0; s < pool_pages_; ++s) {
            const int64_t resident = slot_page_[s];
            if (resident != 0 && last_used_[resident] < oldest) {
                oldest = last_used_[resident];
                slot = s;
            }
        }
        if (slot < 0) return false;
        page_slot_[slot_page_[slot]] = -1;
        ++evictions_;
        ++step.pages_evicted;
    }
    SplatStreamStep::PageWrite write;  // its nodes and splats: ReadPages
    write.page = page;
    write.first_splat = slot * file_.PageCapacity();
    step.writes.push_back(std::move(write));
    slot_page_[slot] = page;
    page_slot_[page] = slot;
    arrived_.push_back(page);
    // Read this step: not evicted again before the next step's cut has had a chance to use it.
    last_used_[page] = step_;
    ++pages_read_;
    bytes_read_ += file_.PageBytes(page);
    return true;
}

void SplatStreamer::ReadPages(SplatStreamStep& step, size_t first_write) {
    // One page per task: the pages are distinct, the file a read-only mapping. On one thread
    // 16 pages of 65,536 splats took 110-150 ms to read and check on the H200 machine
    // (docs/perf/h200-streaming.md), most of it decoding, not the disk.
    core::ParallelFor(
        int64_t(step.writes.size() - first_write),
        [&](int64_t i) {
            SplatStreamStep::PageWrite& write = step.writes[first_write + size_t(i)];
            if (records_[write.page].empty()) records_[write.page] = file_.ReadNodes(write.page);
            write.splats = file_.ReadSplats(write.page);
        },
        1);
}

SplatStreamStep SplatStreamer::Step(const t::geometry::SplatCutView& view, int64_t max_reads) {
    ++step_;
    SplatStreamStep step;
    const auto start = std::chrono::steady_clock::now();
    if (page_slot_[0] < 0) {  // the root: always there, never evicted
        Load(0, step);
        ReadPages(step, 0);  // the cut below starts from its nodes
    }
    // The cut holds distinct nodes of the pool's pages: a budget of at least the pool's
    // splats (or the leaves) cannot bind.
    if (budget_ < std::min(file_.NumLeaves(), PoolSplats())) {
        OrderedCut(view);
    } else {
        UnorderedCut(view);
    }
    for (int64_t page : used_pages_) last_used_[page] = step_;
    std::vector<std::pair<double, int64_t>> wanted;
    std::vector<int64_t> still_waiting;
    for (int64_t page : waiting_pages_) {
        if (waiting_[page].empty()) continue;
        still_waiting.push_back(page);
        wanted.push_back({waiting_size_[page], page});
    }
    waiting_pages_.swap(still_waiting);
    std::sort(wanted.begin(), wanted.end(), std::greater<>());
    step.cut_ms = core::MillisecondsSince(start);
    // The pages read now show from the next step's cut on: one cut per step, since a cut of
    // millions of nodes takes as long as reading many pages.
    const size_t first_read = step.writes.size();
    for (const auto& [priority, page] : wanted) {
        if (int64_t(step.writes.size()) >= max_reads) break;
        if (!Load(page, step)) {
            step.starved = true;
            break;
        }
    }
    ReadPages(step, first_read);
    step.read_ms = core::MillisecondsSince(start) - step.cut_ms;
    step.pages_wanted = static_cast<int64_t>(wanted.size());
    step.visibility.assign((PoolSplats() + 31) / 32, 0u);
    for (const auto& [id, page] : drawn_) {
        if (id < 0) continue;
        const int64_t s =
            page_slot_[page] * file_.PageCapacity() + (id - file_.Page(page).first_node);
        step.visibility[s / 32] |= 1u << (s % 32);
        ++step.cut_nodes;
    }
    step.resident_pages = ResidentPages();
    step.pages_read = pages_read_;
    step.bytes_read = bytes_read_;
    step.evictions = evictions_;
    return step;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
