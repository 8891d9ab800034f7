#include "open3d/t/io/SplatPageFile.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <memory>

#include "open3d/core/Exception.h"
#include "open3d/core/Progress.h"
#include "open3d/t/io/SplatColumns.h"

namespace open3d {
namespace t {
namespace io {

namespace {

static_assert(std::endian::native == std::endian::little,
              "the paged splat file is little-endian and read by memcpy");

constexpr char kMagic[8] = {'O', '3', 'D', 'G', 'S', 'P', 'A', 'G'};
constexpr uint32_t kVersion = 1;
constexpr int kMaxChildren = 8;
// magic, version, SH degree, 4 int64 counts, 6 float64 bounds.
constexpr size_t kHeaderBytes = 8 + 4 + 4 + 4 * 8 + 6 * 8;
constexpr size_t kPageEntryBytes = 3 * 8;

int NumRest(int degree) { return (degree + 1) * (degree + 1) - 1; }
uint64_t BytesPerNode(int num_rest) {
    return sizeof(SplatPageNode) + 4 * uint64_t(14 + 3 * num_rest);
}

template <typename T>
T Load(const uint8_t* at) {
    T value;
    std::memcpy(&value, at, sizeof(T));
    return value;
}
template <typename T>
void Store(std::vector<uint8_t>& out, const T& value) {
    const auto* bytes = reinterpret_cast<const uint8_t*>(&value);
    out.insert(out.end(), bytes, bytes + sizeof(T));
}

// The file order of the hierarchy's nodes and where each page starts in it. A page takes a
// group of children (the root alone first) and then, breadth first, the children groups of
// what it holds while they fit; the groups left over begin later pages in the order they
// were found, so coarse levels come first. A page with room left takes the next pending
// group, so pages stay full where subtrees are small.
struct PageLayout {
    std::vector<int64_t> order;          // file id -> hierarchy node id
    std::vector<int64_t> page_first{0};  // page p: order[page_first[p] .. page_first[p + 1])
};
PageLayout PlacePages(const geometry::SplatHierarchy& h, int64_t capacity) {
    PageLayout layout;
    layout.order.reserve(h.NumNodes());
    const auto members = [&](int64_t group, int64_t& begin, int64_t& end) {
        // group -1: the root alone; else the children of inner node `group`.
        if (group < 0) {
            begin = end = -1;
            return int64_t(1);
        }
        begin = h.child_offsets[group];
        end = h.child_offsets[group + 1];
        return end - begin;
    };
    std::deque<int64_t> pending = {-1};
    while (!pending.empty()) {
        const int64_t start = static_cast<int64_t>(layout.order.size());
        std::deque<int64_t> local;
        while (true) {
            if (local.empty()) {
                if (pending.empty()) break;
                int64_t b, e;
                if (int64_t(layout.order.size()) - start + members(pending.front(), b, e) >
                    capacity) {
                    break;
                }
                local.push_back(pending.front());
                pending.pop_front();
            }
            int64_t begin, end;
            const int64_t size = members(local.front(), begin, end);
            if (int64_t(layout.order.size()) - start + size > capacity) break;
            const int64_t group = local.front();
            local.pop_front();
            const auto place = [&](int64_t node) {
                layout.order.push_back(node);
                if (node >= h.num_leaves) local.push_back(node - h.num_leaves);
            };
            if (group < 0) {
                place(h.Root());
            } else {
                for (int64_t c = begin; c < end; ++c) place(h.children[c]);
            }
        }
        for (int64_t group : local) pending.push_back(group);
        layout.page_first.push_back(static_cast<int64_t>(layout.order.size()));
    }
    return layout;
}

}  // namespace

void WriteSplatPages(const std::string& filename, const geometry::PointCloud& source,
                     const geometry::SplatHierarchy& hierarchy, int64_t page_capacity) {
    if (page_capacity < kMaxChildren) {
        core::ThrowError("WriteSplatPages '{}': a page must hold at least {} nodes, not {}",
                         filename, kMaxChildren, page_capacity);
    }
    const geometry::GaussianSplatArrays leaves = source.GetGaussianSplatArrays();
    if (leaves.num_points != hierarchy.num_leaves || hierarchy.num_leaves < 1) {
        core::ThrowError("WriteSplatPages '{}': the source has {} splats, the hierarchy {} leaves",
                         filename, leaves.num_points, hierarchy.num_leaves);
    }
    const geometry::GaussianSplatArrays inner = hierarchy.inner.IsEmpty()
                                                    ? geometry::GaussianSplatArrays{}
                                                    : hierarchy.inner.GetGaussianSplatArrays();
    if (hierarchy.NumInner() > 0 &&
        (inner.num_points != hierarchy.NumInner() || inner.sh_degree != leaves.sh_degree)) {
        core::ThrowError("WriteSplatPages '{}': the hierarchy's inner nodes do not match it",
                         filename);
    }
    const int64_t n = hierarchy.NumNodes();
    const int num_rest = leaves.num_rest;
    const auto arrays = [&](int64_t node, int64_t& row) -> const geometry::GaussianSplatArrays& {
        row = node < hierarchy.num_leaves ? node : node - hierarchy.num_leaves;
        return node < hierarchy.num_leaves ? leaves : inner;
    };
    const auto radius = [&](int64_t node) {
        int64_t row;
        const float* s = arrays(node, row).scale + 3 * row;
        return 3.0 * std::max({std::abs(s[0]), std::abs(s[1]), std::abs(s[2])});
    };
    const auto centre = [&](int64_t node) {
        int64_t row;
        const float* p = arrays(node, row).positions + 3 * row;
        return Eigen::Vector3d(p[0], p[1], p[2]);
    };

    // Bounding spheres, children first (they have smaller ids), and the centres' box.
    std::vector<double> bound(n);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
    for (int64_t node = 0; node < n; ++node) {
        const Eigen::Vector3d c = centre(node);
        lo = lo.cwiseMin(c);
        hi = hi.cwiseMax(c);
        double b = radius(node);
        if (node >= hierarchy.num_leaves) {
            const int64_t k = node - hierarchy.num_leaves;
            for (int64_t i = hierarchy.child_offsets[k]; i < hierarchy.child_offsets[k + 1]; ++i) {
                const int64_t child = hierarchy.children[i];
                b = std::max(b, (centre(child) - c).norm() + bound[child]);
            }
        }
        bound[node] = b;
    }

    const PageLayout layout = PlacePages(hierarchy, page_capacity);
    std::vector<int64_t> file_id(n);
    for (int64_t f = 0; f < n; ++f) file_id[layout.order[f]] = f;
    const int64_t num_pages = static_cast<int64_t>(layout.page_first.size()) - 1;

    std::vector<uint8_t> header;
    header.insert(header.end(), kMagic, kMagic + 8);
    Store(header, kVersion);
    Store(header, uint32_t(leaves.sh_degree));
    for (int64_t v : {n, hierarchy.num_leaves, num_pages, page_capacity}) Store(header, v);
    for (int axis = 0; axis < 3; ++axis) Store(header, lo[axis]);
    for (int axis = 0; axis < 3; ++axis) Store(header, hi[axis]);
    uint64_t offset = kHeaderBytes + kPageEntryBytes * num_pages;
    for (int64_t p = 0; p < num_pages; ++p) {
        const int64_t count = layout.page_first[p + 1] - layout.page_first[p];
        Store(header, layout.page_first[p]);
        Store(header, count);
        Store(header, offset);
        offset += count * BytesPerNode(num_rest);
    }

    std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(filename.c_str(), "wb"), &std::fclose);
    if (!file) core::ThrowError("Cannot open '{}' for writing: {}", filename, std::strerror(errno));
    const auto write = [&](const std::vector<uint8_t>& bytes) {
        if (std::fwrite(bytes.data(), 1, bytes.size(), file.get()) != bytes.size()) {
            core::ThrowError("Cannot write '{}': {}", filename, std::strerror(errno));
        }
    };
    write(header);
    const std::vector<SplatAttribute> attributes = SplatAttributesInFileOrder(num_rest);
    std::vector<uint8_t> page;
    for (int64_t p = 0; p < num_pages; ++p) {
        core::ReportProgress("writing pages", double(p) / num_pages);
        page.clear();
        const int64_t first = layout.page_first[p], last = layout.page_first[p + 1];
        for (int64_t f = first; f < last; ++f) {
            const int64_t node = layout.order[f];
            const Eigen::Vector3d c = centre(node);
            SplatPageNode record;
            for (int axis = 0; axis < 3; ++axis) record.position[axis] = float(c[axis]);
            record.radius = float(radius(node));
            // Rounded up, so that the float sphere still holds what the double one does.
            record.bound_radius = std::nextafter(float(bound[node]), INFINITY);
            record.source_id = node;
            if (node >= hierarchy.num_leaves) {
                const int64_t k = node - hierarchy.num_leaves;
                record.num_children =
                    uint32_t(hierarchy.child_offsets[k + 1] - hierarchy.child_offsets[k]);
                record.first_child = file_id[hierarchy.children[hierarchy.child_offsets[k]]];
            }
            Store(page, record);
        }
        for (const SplatAttribute& a : attributes) {
            for (int64_t f = first; f < last; ++f) {
                int64_t row;
                const geometry::GaussianSplatArrays& from = arrays(layout.order[f], row);
                const float* values =
                    a.name == std::string(geometry::gs_attr::kPositions) ? from.positions
                    : a.name == std::string(geometry::gs_attr::kScale)   ? from.scale
                    : a.name == std::string(geometry::gs_attr::kRot)     ? from.rot
                    : a.name == std::string(geometry::gs_attr::kOpacity) ? from.opacity
                    : a.name == std::string(geometry::gs_attr::kFDc)     ? from.f_dc
                                                                         : from.f_rest;
                const auto* bytes = reinterpret_cast<const uint8_t*>(values + a.width * row);
                page.insert(page.end(), bytes, bytes + 4 * a.width);
            }
        }
        write(page);
    }
    if (std::fflush(file.get()) != 0) {
        core::ThrowError("Cannot write '{}': {}", filename, std::strerror(errno));
    }
    core::ReportProgress("writing pages", 1.0);
}

SplatPageFile::SplatPageFile(const std::string& filename) : filename_(filename) {
    file_ = std::make_unique<MappedFile>(filename, /*populate=*/false);
    const uint8_t* data = file_->data();
    const uint64_t size = file_->size();
    if (size < kHeaderBytes || std::memcmp(data, kMagic, 8) != 0) {
        Fail("not a paged splat file (no O3DGSPAG header)");
    }
    const uint32_t version = Load<uint32_t>(data + 8);
    if (version != kVersion) Fail("version " + std::to_string(version) + ", expected 1");
    const uint32_t degree = Load<uint32_t>(data + 12);
    if (degree > 3) Fail("SH degree " + std::to_string(degree));
    sh_degree_ = int(degree);
    num_nodes_ = Load<int64_t>(data + 16);
    num_leaves_ = Load<int64_t>(data + 24);
    const int64_t num_pages = Load<int64_t>(data + 32);
    page_capacity_ = Load<int64_t>(data + 40);
    for (int axis = 0; axis < 3; ++axis) {
        center_min_[axis] = Load<double>(data + 48 + 8 * axis);
        center_max_[axis] = Load<double>(data + 72 + 8 * axis);
    }
    if (num_leaves_ < 1 || num_nodes_ < num_leaves_ || num_nodes_ > (int64_t(1) << 40)) {
        Fail("node counts " + std::to_string(num_nodes_) + " / " + std::to_string(num_leaves_) +
             " leaves");
    }
    if (page_capacity_ < kMaxChildren || page_capacity_ > INT32_MAX) {
        Fail("page capacity " + std::to_string(page_capacity_));
    }
    if (num_pages < 1 || num_pages > num_nodes_ ||
        uint64_t(num_pages) > (size - kHeaderBytes) / kPageEntryBytes) {
        Fail("page count " + std::to_string(num_pages) + " does not fit the file");
    }
    if (!center_min_.allFinite() || !center_max_.allFinite() ||
        (center_min_.array() > center_max_.array()).any()) {
        Fail("centre bounds that are not a box");
    }
    const uint64_t per_node = BytesPerNode(NumRest(sh_degree_));
    uint64_t offset = kHeaderBytes + kPageEntryBytes * num_pages;
    int64_t first = 0;
    pages_.resize(num_pages);
    for (int64_t p = 0; p < num_pages; ++p) {
        const uint8_t* entry = data + kHeaderBytes + kPageEntryBytes * p;
        SplatPageInfo& info = pages_[p];
        info.first_node = Load<int64_t>(entry);
        info.num_nodes = Load<int64_t>(entry + 8);
        info.offset = Load<uint64_t>(entry + 16);
        if (info.first_node != first || info.num_nodes < 1 || info.num_nodes > page_capacity_ ||
            info.offset != offset) {
            Fail("page " + std::to_string(p) + "'s entry does not follow the page before it");
        }
        first += info.num_nodes;
        offset += info.num_nodes * per_node;
        if (first > num_nodes_ || offset > size) {
            Fail("page " + std::to_string(p) + " runs past the file's nodes or bytes");
        }
    }
    if (first != num_nodes_ || offset != size) {
        Fail("the pages hold " + std::to_string(first) + " nodes in " + std::to_string(offset) +
             " bytes; the header says " + std::to_string(num_nodes_) + " nodes and the file has " +
             std::to_string(size) + " bytes");
    }
}

SplatPageFile::~SplatPageFile() = default;

uint64_t SplatPageFile::FileBytes() const { return file_->size(); }

void SplatPageFile::Fail(const std::string& what) const {
    core::ThrowError("Paged splat file '{}': {}", filename_, what);
}

int64_t SplatPageFile::PageOfNode(int64_t node) const {
    if (node < 0 || node >= num_nodes_) Fail("no node " + std::to_string(node));
    const auto it = std::upper_bound(
        pages_.begin(), pages_.end(), node,
        [](int64_t id, const SplatPageInfo& page) { return id < page.first_node; });
    return static_cast<int64_t>(it - pages_.begin()) - 1;
}

uint64_t SplatPageFile::PageBytes(int64_t page) const {
    return Page(page).num_nodes * BytesPerNode(NumRest(sh_degree_));
}

std::vector<SplatPageNode> SplatPageFile::ReadNodes(int64_t page) const {
    const SplatPageInfo& info = Page(page);
    std::vector<SplatPageNode> nodes(info.num_nodes);
    std::memcpy(nodes.data(), file_->data() + info.offset, nodes.size() * sizeof(SplatPageNode));
    for (int64_t i = 0; i < info.num_nodes; ++i) {
        const SplatPageNode& node = nodes[i];
        const int64_t id = info.first_node + i;
        const auto fail = [&](const std::string& what) {
            Fail("page " + std::to_string(page) + ", node " + std::to_string(id) + ": " + what);
        };
        if (!std::isfinite(node.position[0]) || !std::isfinite(node.position[1]) ||
            !std::isfinite(node.position[2]) || !(node.radius >= 0) ||
            !(node.bound_radius >= node.radius) || !std::isfinite(node.bound_radius)) {
            fail("a non-finite or negative position, radius or bound");
        }
        if (node.num_children == 0) {
            if (node.source_id < 0 || node.source_id >= num_leaves_) fail("a leaf's source id");
            continue;
        }
        if (node.num_children < 2 || node.num_children > kMaxChildren) {
            fail(std::to_string(node.num_children) + " children (2 to 8)");
        }
        if (node.source_id < num_leaves_ || node.source_id >= num_nodes_) {
            fail("an inner node's source id");
        }
        const int64_t last = node.first_child + node.num_children - 1;
        if (node.first_child <= id || last >= num_nodes_ ||
            PageOfNode(node.first_child) != PageOfNode(last)) {
            fail("children that are not after it and in one page");
        }
    }
    return nodes;
}

geometry::PointCloud SplatPageFile::ReadSplats(int64_t page) const {
    const SplatPageInfo& info = Page(page);
    const int64_t n = info.num_nodes;
    const int num_rest = NumRest(sh_degree_);
    const uint8_t* at = file_->data() + info.offset + n * sizeof(SplatPageNode);
    geometry::PointCloud cloud =
        ReadSplatAttributeBlocks(at, n, num_rest, [&](const char* name, int64_t row) {
            Fail("page " + std::to_string(page) + ": a non-finite " + name + " of node " +
                 std::to_string(info.first_node + row));
        });
    const float* v = cloud.GetPointPositions().Data<float>();
    for (int64_t i = 0; i < 3 * n; ++i) {
        if (v[i] < center_min_[i % 3] || v[i] > center_max_[i % 3]) {
            Fail("page " + std::to_string(page) + ": node " +
                 std::to_string(info.first_node + i / 3) +
                 "'s centre lies outside the header's bounds");
        }
    }
    return cloud;
}

}  // namespace io
}  // namespace t
}  // namespace open3d
