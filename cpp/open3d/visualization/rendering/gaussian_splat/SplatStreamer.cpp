#include "open3d/visualization/rendering/gaussian_splat/SplatStreamer.h"

#include <algorithm>
#include <chrono>
#include <queue>

#include "open3d/core/Exception.h"
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
    page_slot_.assign(file.NumPages(), -1);
    slot_page_.assign(pool_pages, -1);
    last_used_.assign(file.NumPages(), 0);
}

int64_t SplatStreamer::ResidentPages() const {
    return std::count_if(slot_page_.begin(), slot_page_.end(), [](int64_t p) { return p >= 0; });
}

SplatStreamer::Cut SplatStreamer::MakeCut(const t::geometry::SplatCutView& view) {
    // The greedy cut of CutSplatHierarchy (largest projected size opens first, a node whose
    // children do not fit the budget stays whole) over the pages in the pool: a node whose
    // children's page is not there stays whole too, and asks for that page. A budget of at
    // least the leaves never binds (a cut holds at most every leaf), and then the order in
    // which nodes open does not matter: a stack replaces the priority queue.
    const Eigen::Matrix3d r = view.world_to_camera.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = view.world_to_camera.topRightCorner<3, 1>();
    const bool ordered = budget_ < file_.NumLeaves();
    struct Open {
        double size;
        int64_t id, page;
        bool operator<(const Open& o) const { return size < o.size; }
    };
    std::priority_queue<Open> heap;
    std::vector<Open> stack;
    Cut cut;
    int64_t count = 0;  // nodes drawn and open
    // Whether `node` is in view; if so, its projected size.
    const auto in_view = [&](const t::io::SplatPageNode& node, double& size) {
        const Eigen::Vector3d c =
            r * Eigen::Vector3d(node.position[0], node.position[1], node.position[2]) + t;
        if (t::geometry::SplatOutsideView(view, c, node.bound_radius)) return false;
        const double radius = node.radius;
        size = view.focal_px * radius / std::max(c.z(), 1e-3 * radius + 1e-30);
        return true;
    };
    const auto add = [&](int64_t id, int64_t page, double size) {
        ++count;
        if (Node(id, page).num_children == 0) {
            cut.drawn.push_back({id, page});
        } else if (ordered) {
            heap.push({size, id, page});
        } else {
            stack.push_back({size, id, page});
        }
    };
    last_used_[0] = step_;
    if (double size; in_view(Node(0, 0), size)) add(0, 0, size);
    std::vector<double> wanted(file_.NumPages(), -1.0);
    std::vector<int64_t> wanted_pages;
    while (ordered ? !heap.empty() : !stack.empty()) {
        Open top;
        if (ordered) {
            top = heap.top();
            heap.pop();
        } else {
            top = stack.back();
            stack.pop_back();
        }
        const t::io::SplatPageNode& node = Node(top.id, top.page);
        const int64_t page = file_.PageOfNode(node.first_child);
        if (page_slot_[page] < 0) {
            cut.drawn.push_back({top.id, top.page});
            if (wanted[page] < 0) wanted_pages.push_back(page);
            wanted[page] = std::max(wanted[page], top.size);
            continue;
        }
        // Children outside the view are dropped, so opening adds the visible ones less one.
        double sizes[8];
        bool visible[8];
        int64_t num_visible = 0;
        for (uint32_t i = 0; i < node.num_children; ++i) {
            visible[i] = in_view(Node(node.first_child + i, page), sizes[i]);
            num_visible += visible[i];
        }
        if (count - 1 + num_visible > budget_) {
            cut.drawn.push_back({top.id, top.page});
            continue;
        }
        last_used_[page] = step_;
        --count;
        for (uint32_t i = 0; i < node.num_children; ++i) {
            if (visible[i]) add(node.first_child + i, page, sizes[i]);
        }
    }
    for (int64_t page : wanted_pages) cut.wanted.push_back({wanted[page], page});
    std::sort(cut.wanted.begin(), cut.wanted.end(), std::greater<>());
    return cut;
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
    if (records_[page].empty()) records_[page] = file_.ReadNodes(page);
    SplatStreamStep::PageWrite write;
    write.page = page;
    write.first_splat = slot * file_.PageCapacity();
    write.splats = file_.ReadSplats(page);
    step.writes.push_back(std::move(write));
    slot_page_[slot] = page;
    page_slot_[page] = slot;
    // Read this step: not evicted again before the next step's cut has had a chance to use it.
    last_used_[page] = step_;
    ++pages_read_;
    bytes_read_ += file_.PageBytes(page);
    return true;
}

SplatStreamStep SplatStreamer::Step(const t::geometry::SplatCutView& view, int64_t max_reads) {
    ++step_;
    SplatStreamStep step;
    const auto start = std::chrono::steady_clock::now();
    if (page_slot_[0] < 0) Load(0, step);  // the root: always there, never evicted
    const Cut cut = MakeCut(view);
    step.cut_ms = core::MillisecondsSince(start);
    // The pages read now show from the next step's cut on: one cut per step, since a cut of
    // millions of nodes takes as long as reading several pages.
    for (const auto& [priority, page] : cut.wanted) {
        if (int64_t(step.writes.size()) >= max_reads) break;
        if (!Load(page, step)) {
            step.starved = true;
            break;
        }
    }
    step.read_ms = core::MillisecondsSince(start) - step.cut_ms;
    step.pages_wanted = static_cast<int64_t>(cut.wanted.size());
    step.cut_nodes = static_cast<int64_t>(cut.drawn.size());
    step.visibility.assign((PoolSplats() + 31) / 32, 0u);
    for (const auto& [id, page] : cut.drawn) {
        const int64_t s =
            page_slot_[page] * file_.PageCapacity() + (id - file_.Page(page).first_node);
        step.visibility[s / 32] |= 1u << (s % 32);
    }
    return step;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
