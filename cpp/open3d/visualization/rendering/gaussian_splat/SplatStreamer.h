// Streaming of a paged splat file (t/io/SplatPageFile.h) through a fixed pool of page slots
// on the GPU (docs/streaming.md). Each Step cuts the hierarchy for a view using only the
// pages in the pool, reads the pages the cut wants next (largest projected node first) into
// free slots or slots whose page the view does not use (least recently used first), and
// returns the slots' new contents and the pool's visibility mask: the cut. The renderer draws
// the pool as one scene of PoolSplats() splats (GaussianSplatVulkanBackend::SetScenePool).
//
// With every page resident and a budget of at least the leaves, the cut draws every leaf the
// view can see: the exact image. Nodes whose bounding sphere (over their whole subtree) lies
// outside the view are neither drawn nor opened: nothing below them colours a pixel.
#pragma once

#include <cstdint>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/SplatPageFile.h"

namespace open3d {
namespace visualization {
namespace rendering {

/// The cut's view of `camera`: its pose, its larger focal length, its image for the frustum.
t::geometry::SplatCutView SplatCutViewOf(const camera::PinholeCamera& camera);

/// What one SplatStreamer::Step changed.
struct SplatStreamStep {
    /// A page read into the pool: its splats go to slots [first_splat, first_splat + n).
    struct PageWrite {
        int64_t page = 0;
        int64_t first_splat = 0;
        t::geometry::PointCloud splats;
    };
    std::vector<PageWrite> writes;     ///< to write before drawing `visibility`
    std::vector<uint32_t> visibility;  ///< [PoolSplats() / 32]: bit s shows pool slot s
    int64_t cut_nodes = 0;             ///< nodes drawn
    int64_t pages_evicted = 0;         ///< pages whose slots this step reused
    /// Pages this step's cut would open into and did not have (those read by this step
    /// show from the next step's cut on); 0 when the cut is what unlimited memory would give
    /// for this view and budget.
    int64_t pages_wanted = 0;
    double cut_ms = 0.0;   ///< host time of the cut
    double read_ms = 0.0;  ///< host time of reading and checking the pages
    /// A wanted page found no slot: every slot holds a page this view's cut uses.
    bool starved = false;
    /// The streamer's totals after this step (ResidentPages, PagesRead, BytesRead,
    /// Evictions), for a thread that must not ask the streamer while it steps.
    int64_t resident_pages = 0;
    int64_t pages_read = 0;
    uint64_t bytes_read = 0;
    int64_t evictions = 0;
};

class SplatStreamer {
public:
    /// Streams `file` (which must outlive the streamer) into `pool_pages` slots of
    /// file.PageCapacity() splats each, with cuts of at most `splat_budget` (>= 1) nodes.
    /// Throws core::Open3DError for a pool of no slot or a budget below 1.
    SplatStreamer(const t::io::SplatPageFile& file, int64_t pool_pages, int64_t splat_budget);

    /// Splat slots of the pool: pool pages x page capacity.
    int64_t PoolSplats() const { return pool_pages_ * file_.PageCapacity(); }
    int64_t PoolPages() const { return pool_pages_; }

    /// Cuts for `view` over the pages in the pool and reads up to `max_reads` of the pages
    /// that cut wants, largest projected node first (the root's page is read on the first
    /// step whatever `max_reads` is). Returns the pages to write and the cut's mask; the pages
    /// read show from the next step on.
    SplatStreamStep Step(const t::geometry::SplatCutView& view, int64_t max_reads);

    int64_t ResidentPages() const;
    int64_t PagesRead() const { return pages_read_; }   ///< since construction
    uint64_t BytesRead() const { return bytes_read_; }  ///< bytes of the pages read
    int64_t Evictions() const { return evictions_; }

    /// Page of every slot (-1 empty), for tests.
    const std::vector<int64_t>& SlotPages() const { return slot_page_; }

private:
    struct Open {
        double size;
        int64_t id, page;
        bool operator<(const Open& o) const { return size < o.size; }
    };
    /// The ordered cut (a budget below the leaves and the pool's splats): from the root,
    /// largest node first.
    void OrderedCut(const t::geometry::SplatCutView& view);
    /// The unordered cut (a budget that cannot bind): from the root when the view changed or
    /// there is no cut yet, else only below the nodes that waited for the pages read since.
    void UnorderedCut(const t::geometry::SplatCutView& view);
    /// Opens the stack's inner nodes and what lies below them in the pool (unordered).
    void Expand(const t::geometry::SplatCutView& view, std::vector<Open>& stack);
    /// Forgets the cut: no node drawn, none waiting, no page used.
    void ClearCut();
    /// The page of `open`'s children when it is in the pool; else `open` stays whole (drawn,
    /// waiting for that page with its size) and the result is -1.
    int64_t ChildrenPageOrWait(const Open& open);
    void UsePage(int64_t page);
    const t::io::SplatPageNode& Node(int64_t id, int64_t page) const {
        return records_[page][id - file_.Page(page).first_node];
    }
    /// Gives `page` a free slot or the least recently used slot this step's cut does not use
    /// (ReadPages reads it); false when there is none.
    bool Load(int64_t page, SplatStreamStep& step);
    /// Reads the nodes and splats of step.writes[first_write...] (pages Load gave slots).
    void ReadPages(SplatStreamStep& step, size_t first_write);

    const t::io::SplatPageFile& file_;
    int64_t pool_pages_ = 0;
    int64_t budget_ = 0;
    /// Node records of every page read so far: they stay when the page's splats leave the
    /// pool (40 bytes a node), so a cut walks what it has seen without reading it again.
    std::vector<std::vector<t::io::SplatPageNode>> records_;
    std::vector<int64_t> page_slot_;   // page -> slot, -1 when not in the pool
    std::vector<int64_t> slot_page_;   // slot -> page, -1 when empty
    std::vector<uint64_t> last_used_;  // page -> the last step whose cut used it
    uint64_t step_ = 0;
    int64_t pages_read_ = 0, evictions_ = 0;

    // The cut: drawn nodes as (id, page), id -1 once opened by a later step (a few entries
    // per page read, kept until the next cut from the root); for each page
    // not in the pool, the drawn nodes (indices into drawn_) that wait for it and the
    // largest of their projected sizes; the pages the cut opened into.
    std::vector<std::pair<int64_t, int64_t>> drawn_;
    std::vector<std::vector<int64_t>> waiting_;
    std::vector<double> waiting_size_;
    std::vector<int64_t> waiting_pages_;  // pages with waiters (some may have none left)
    std::vector<int64_t> used_pages_;
    std::vector<char> page_used_;
    std::vector<int64_t> arrived_;        // pages read since the last cut
    bool have_cut_ = false;               // an unordered cut that a step may extend
    t::geometry::SplatCutView cut_view_;  // the view it was made for
    uint64_t bytes_read_ = 0;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
