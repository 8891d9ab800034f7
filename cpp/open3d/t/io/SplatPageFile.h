// The paged splat file (docs/streaming.md): a scene's level-of-detail hierarchy cut into
// pages of at most a fixed number of nodes, each page one contiguous byte range holding its
// nodes' records (what a cut needs) and their Gaussians, so that a renderer reads a page at
// a time through a memory mapping and keeps only some of them on the GPU.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/SplatHierarchy.h"

namespace open3d {
namespace t {
namespace io {

class MappedFile;

/// One node as a cut sees it, without its Gaussian (40 bytes in the file). Node ids are the
/// file's: the root is node 0, a node's children are consecutive and in one page, and every
/// child has a larger id than its parent.
struct SplatPageNode {
    float position[3] = {0, 0, 0};  ///< the Gaussian's mean
    float radius = 0;               ///< 3 x its largest scale: what its projected size is from
    /// A sphere about `position` that holds the 3-sigma spheres of the node and of every
    /// node below it: a view that misses it misses all of them.
    float bound_radius = 0;
    uint32_t num_children = 0;  ///< 0 (a leaf) or 2..8
    int64_t first_child = 0;    ///< id of the first child (leaves: 0)
    int64_t source_id = 0;      ///< its id in the SplatHierarchy (< leaves: a source splat)
};
static_assert(sizeof(SplatPageNode) == 40, "the file's node record");

/// Where page p lies: nodes [first_node, first_node + num_nodes), bytes from `offset`.
struct SplatPageInfo {
    int64_t first_node = 0;
    int64_t num_nodes = 0;
    uint64_t offset = 0;
};

/// Writes `hierarchy` (built from `source`) as pages of at most `page_capacity` (>= 8) nodes.
/// Pages are filled top-down: the root's page first, then, breadth first, the groups of
/// children below it while they fit; a group that does not fit begins a later page, so the
/// coarse levels come first and a page is a few levels of one region. Reports progress as
/// "writing pages". Throws core::Open3DError naming the file when it cannot be written or
/// the inputs disagree.
void WriteSplatPages(const std::string& filename, const geometry::PointCloud& source,
                     const geometry::SplatHierarchy& hierarchy, int64_t page_capacity);

/// A paged splat file, mapped and read a page at a time. Opening reads the header and the
/// page table only (and checks that they describe the file's exact length); each page is
/// checked when it is read. Every error names the file and what is wrong.
class SplatPageFile {
public:
    explicit SplatPageFile(const std::string& filename);
    ~SplatPageFile();
    SplatPageFile(const SplatPageFile&) = delete;
    SplatPageFile& operator=(const SplatPageFile&) = delete;

    const std::string& GetFilename() const { return filename_; }
    int ShDegree() const { return sh_degree_; }
    int64_t NumNodes() const { return num_nodes_; }
    int64_t NumLeaves() const { return num_leaves_; }
    int64_t NumPages() const { return static_cast<int64_t>(pages_.size()); }
    int64_t PageCapacity() const { return page_capacity_; }
    /// Bounds of every node's centre (the renderer's depth range comes from them).
    const Eigen::Vector3d& CenterMin() const { return center_min_; }
    const Eigen::Vector3d& CenterMax() const { return center_max_; }
    uint64_t FileBytes() const;

    const SplatPageInfo& Page(int64_t page) const { return pages_.at(page); }
    /// The page holding `node`.
    int64_t PageOfNode(int64_t node) const;
    /// Bytes of page p in the file (records and Gaussians).
    uint64_t PageBytes(int64_t page) const;

    /// Page p's node records, checked: children counts, children in one page after their
    /// parent, leaves with source ids below NumLeaves() and inner nodes above, finite values.
    std::vector<SplatPageNode> ReadNodes(int64_t page) const;
    /// Page p's Gaussians, its nodes in order, as a splat cloud of the file's SH degree;
    /// centres outside the header's bounds and non-finite values are refused.
    geometry::PointCloud ReadSplats(int64_t page) const;

private:
    [[noreturn]] void Fail(const std::string& what) const;

    std::string filename_;
    std::unique_ptr<MappedFile> file_;
    int sh_degree_ = 0;
    int64_t num_nodes_ = 0, num_leaves_ = 0, page_capacity_ = 0;
    Eigen::Vector3d center_min_, center_max_;
    std::vector<SplatPageInfo> pages_;
};

}  // namespace io
}  // namespace t
}  // namespace open3d
