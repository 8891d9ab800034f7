// The paged splat file: every node of the hierarchy lands in one page with its Gaussian
// bit for bit and its children in one later-or-same page, pages stay within their capacity
// with the coarse levels first, bounding spheres hold their subtrees, and malformed files
// are refused with the file's name and what is wrong.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "RandomSplatCloud.h"
#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/SplatPageFile.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using geometry::PointCloud;
using geometry::SplatHierarchy;

// Row `row` of a splat cloud as raw floats, attribute after attribute.
std::vector<float> RowFloats(const PointCloud& from, int64_t row) {
    std::vector<float> out;
    for (const char* name : {"positions", "scale", "rot", "opacity", "f_dc", "f_rest"}) {
        if (!from.HasPointAttr(name)) continue;
        const core::Tensor& t = from.GetPointAttr(name);
        const int64_t width = t.NumElements() / t.GetShape(0);
        const float* v = t.Data<float>() + row * width;
        out.insert(out.end(), v, v + width);
    }
    return out;
}
// The Gaussian of hierarchy node `id`.
std::vector<float> NodeFloats(const PointCloud& source, const SplatHierarchy& h, int64_t id) {
    return id < h.num_leaves ? RowFloats(source, id) : RowFloats(h.inner, id - h.num_leaves);
}

TEST(SplatPageFile, EveryNodeOnceWithItsGaussianAndChildren) {
    const std::string dir = tests::TempDir();
    for (const int degree : {0, 2}) {
        for (const int64_t capacity : {int64_t(8), int64_t(40), int64_t(100000)}) {
            SCOPED_TRACE("degree " + std::to_string(degree) + ", capacity " +
                         std::to_string(capacity));
            const PointCloud cloud = RandomCloud(600, degree, 5 + degree);
            const SplatHierarchy h = geometry::BuildSplatHierarchy(cloud);
            const std::string path = dir + "/scene.gspages";
            WriteSplatPages(path, cloud, h, capacity);
            const SplatPageFile file(path);
            ASSERT_EQ(file.NumNodes(), h.NumNodes());
            ASSERT_EQ(file.NumLeaves(), h.num_leaves);
            EXPECT_EQ(file.ShDegree(), degree);
            if (capacity >= h.NumNodes()) {
                EXPECT_EQ(file.NumPages(), 1);
            }
            std::vector<SplatPageNode> nodes;
            std::vector<std::vector<float>> floats;
            for (int64_t p = 0; p < file.NumPages(); ++p) {
                EXPECT_LE(file.Page(p).num_nodes, capacity);
                const std::vector<SplatPageNode> page = file.ReadNodes(p);
                const PointCloud splats = file.ReadSplats(p);
                ASSERT_EQ(splats.NumPoints(), int64_t(page.size()));
                nodes.insert(nodes.end(), page.begin(), page.end());
                for (int64_t i = 0; i < splats.NumPoints(); ++i) {
                    floats.push_back(RowFloats(splats, i));
                }
            }
            ASSERT_EQ(int64_t(nodes.size()), h.NumNodes());
            EXPECT_EQ(nodes[0].source_id, h.Root());
            std::vector<int> seen(h.NumNodes(), 0);
            for (int64_t f = 0; f < h.NumNodes(); ++f) {
                const SplatPageNode& node = nodes[f];
                const int64_t id = node.source_id;
                ASSERT_TRUE(id >= 0 && id < h.NumNodes());
                ++seen[id];
                EXPECT_EQ(floats[f], NodeFloats(cloud, h, id)) << "node " << id;
                const Eigen::Vector3f centre(node.position[0], node.position[1], node.position[2]);
                if (id < h.num_leaves) {
                    EXPECT_EQ(node.num_children, 0u);
                    continue;
                }
                // Its children in the file are its children in the hierarchy, in one page not
                // before its own, each sphere inside its bound.
                const int64_t k = id - h.num_leaves;
                std::vector<int64_t> expected(h.children.begin() + h.child_offsets[k],
                                              h.children.begin() + h.child_offsets[k + 1]);
                std::vector<int64_t> got;
                for (uint32_t c = 0; c < node.num_children; ++c) {
                    const SplatPageNode& child = nodes[node.first_child + c];
                    got.push_back(child.source_id);
                    const Eigen::Vector3f at(child.position[0], child.position[1],
                                             child.position[2]);
                    // Bounds are computed in double and rounded up to float; the float
                    // centres' distance differs from the double one by ~1e-6 relative.
                    EXPECT_LE((at - centre).norm() + child.bound_radius,
                              node.bound_radius * (1 + 1e-5f));
                }
                EXPECT_EQ(got, expected);
                EXPECT_GE(file.PageOfNode(node.first_child), file.PageOfNode(f));
                EXPECT_EQ(file.PageOfNode(node.first_child),
                          file.PageOfNode(node.first_child + node.num_children - 1));
            }
            EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), h.NumNodes());
        }
    }
}

// Opening and reading every page of `bytes` fails with a message holding `expected`.
void ExpectRefused(const std::string& path, const std::vector<uint8_t>& bytes,
                   const std::string& expected) {
    tests::WriteFileBytes(path, bytes);
    try {
        const SplatPageFile file(path);
        for (int64_t p = 0; p < file.NumPages(); ++p) {
            file.ReadNodes(p);
            file.ReadSplats(p);
        }
        ADD_FAILURE() << "accepted; expected an error with '" << expected << "'";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
}

TEST(SplatPageFile, MalformedFilesAreRefused) {
    const std::string dir = tests::TempDir();
    const PointCloud cloud = RandomCloud(50, 1, 3);
    const SplatHierarchy h = geometry::BuildSplatHierarchy(cloud);
    const std::string good = dir + "/good.gspages", bad = dir + "/bad.gspages";
    WriteSplatPages(good, cloud, h, 16);
    const std::vector<uint8_t> bytes = tests::ReadFileBytes(good);
    const SplatPageFile file(good);
    ASSERT_GT(file.NumPages(), 2);
    const size_t table = 96;  // header bytes; page entries follow
    {
        std::vector<uint8_t> b = bytes;
        b[3] = 'X';
        ExpectRefused(bad, b, "no O3DGSPAG header");
    }
    {
        std::vector<uint8_t> b = bytes;
        b.resize(b.size() - 1);
        ExpectRefused(bad, b, "runs past the file's nodes or bytes");
    }
    {
        std::vector<uint8_t> b = bytes;
        b[table + 24 + 8] += 1;  // page 1's node count: page 2 no longer starts after it
        ExpectRefused(bad, b, "page 2's entry does not follow");
    }
    {
        // Page 0's first record (the root): 9 children.
        std::vector<uint8_t> b = bytes;
        const uint32_t nine = 9;
        std::memcpy(b.data() + file.Page(0).offset + 20, &nine, 4);
        ExpectRefused(bad, b, "9 children");
    }
    {
        // The root's first child pointing at itself.
        std::vector<uint8_t> b = bytes;
        const int64_t self = 0;
        std::memcpy(b.data() + file.Page(0).offset + 24, &self, 8);
        ExpectRefused(bad, b, "children that are not after it");
    }
    {
        // A NaN opacity in the last page.
        std::vector<uint8_t> b = bytes;
        const SplatPageInfo& last = file.Page(file.NumPages() - 1);
        const size_t opacity = last.offset + last.num_nodes * (40 + 4 * 10);
        const float nan = std::numeric_limits<float>::quiet_NaN();
        std::memcpy(b.data() + opacity, &nan, 4);
        ExpectRefused(bad, b, "non-finite opacity");
    }
    EXPECT_THROW(WriteSplatPages(bad, cloud, h, 7), core::Open3DError);
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
