// Selecting, cropping and removing rows of a cloud (PointCloudSelect.cpp, BoundingBox.h): every
// attribute of the kept rows must be the source's bit for bit, whatever its dtype; boxes are
// closed; a bad argument is refused before anything is copied; and an edit commutes with
// writing and reading every format that encodes each splat on its own.
#include <gtest/gtest.h>

#include "RandomGeometry.h"

#include <Eigen/Dense>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/BoundingBox.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace geometry {
namespace {

using core::Dtype;
using core::Tensor;

// n splats of SH degree 3 in [-5, 5)^3, with a uint8 label attribute beside them.
PointCloud MakeSplats(int64_t n, bool with_label, uint32_t seed = 7) {
    PointCloud cloud = MakeSplatCloud(n, 3, seed);
    if (with_label) {
        Tensor label({n, 1}, Dtype::UInt8);
        for (int64_t i = 0; i < n; ++i) label.Data<uint8_t>()[i] = uint8_t(i * 37);
        cloud.SetPointAttr("label", label);
    }
    return cloud;
}

// Row `row` of every attribute of `a` equals row `source_row` of `b`, byte for byte.
void ExpectRowEqual(const PointCloud& a, int64_t row, const PointCloud& b, int64_t source_row) {
    ASSERT_EQ(a.GetPointAttrNames(), b.GetPointAttrNames());
    for (const std::string& name : a.GetPointAttrNames()) {
        const Tensor& x = a.GetPointAttr(name);
        const Tensor& y = b.GetPointAttr(name);
        const int64_t bytes = y.NumBytes() / y.GetShape(0);
        ASSERT_EQ(x.NumBytes() / std::max<int64_t>(x.GetShape(0), 1), bytes) << name;
        EXPECT_EQ(std::memcmp(static_cast<const uint8_t*>(x.RawData()) + row * bytes,
                              static_cast<const uint8_t*>(y.RawData()) + source_row * bytes,
                              size_t(bytes)),
                  0)
            << name << " of row " << row << " (source row " << source_row << ")";
    }
}

PointCloud Read(const std::string& path) {
    PointCloud cloud;
    io::ReadPointCloud(path, cloud);
    return cloud;
}

TEST(PointCloudSelect, SelectByIndexKeepsOrderRepeatsAndEveryAttribute) {
    const PointCloud cloud = MakeSplats(50, true);
    const std::vector<int64_t> indices{7, 3, 3, 49, 0};
    const PointCloud picked = cloud.SelectByIndex(indices);
    ASSERT_EQ(picked.NumPoints(), 5);
    for (size_t k = 0; k < indices.size(); ++k)
        ExpectRowEqual(picked, int64_t(k), cloud, indices[k]);
    const PointCloud rest = cloud.SelectByIndex(indices, /*invert=*/true);
    ASSERT_EQ(rest.NumPoints(), 46);  // 50 minus the four distinct rows
    int64_t k = 0;
    for (int64_t i = 0; i < 50; ++i) {
        if (i == 0 || i == 3 || i == 7 || i == 49) continue;
        ExpectRowEqual(rest, k++, cloud, i);
    }
    EXPECT_EQ(cloud.RemoveByIndex(indices), rest);
    EXPECT_EQ(cloud.SelectByIndex({}).NumPoints(), 0);
    EXPECT_EQ(cloud.SelectByIndex({}, true), cloud);
    EXPECT_THROW(cloud.SelectByIndex({50}), core::Open3DError);
    EXPECT_THROW(cloud.SelectByIndex({-1}, true), core::Open3DError);
}

TEST(PointCloudSelect, SelectByMaskTakesOneEntryAPoint) {
    const PointCloud cloud = MakeSplats(20, true);
    std::vector<bool> mask(20, false);
    mask[2] = mask[5] = mask[19] = true;
    const PointCloud picked = cloud.SelectByMask(mask);
    ASSERT_EQ(picked.NumPoints(), 3);
    ExpectRowEqual(picked, 0, cloud, 2);
    ExpectRowEqual(picked, 2, cloud, 19);
    EXPECT_EQ(cloud.SelectByMask(mask, true).NumPoints(), 17);
    try {
        cloud.SelectByMask(std::vector<bool>(19, true));
        ADD_FAILURE() << "a mask of 19 entries for 20 points";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("19 entries for 20 points"), std::string::npos)
            << e.what();
    }
}

TEST(PointCloudSelect, CropKeepsThePointsInsideTheClosedBox) {
    // Positions on the faces, just outside them, and inside, by hand.
    Tensor positions({6, 3}, Dtype::Float32);
    const float p[6][3] = {{0, 0, 0},  {1, 2, 3},       {1, 0, 0},
                           {-1, 0, 0}, {1.0001f, 0, 0}, {0.5f, 2.5f, 3}};
    std::memcpy(positions.Data<float>(), p, sizeof(p));
    const PointCloud cloud(positions);
    const AxisAlignedBoundingBox box(Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(1, 2, 3));
    const PointCloud inside = cloud.Crop(box);
    ASSERT_EQ(inside.NumPoints(), 4);  // rows 0, 1, 2, 3: 1.0001 and y = 2.5 are outside
    for (int64_t k = 0; k < 4; ++k) ExpectRowEqual(inside, k, cloud, k);
    EXPECT_EQ(cloud.Crop(box, true).NumPoints(), 2);
    EXPECT_EQ(cloud.Crop(AxisAlignedBoundingBox()).NumPoints(), 0);  // empty box
    EXPECT_EQ(cloud.Crop(OrientedBoundingBox::FromAxisAligned(box)), inside);
    const AxisAlignedBoundingBox bounds = cloud.GetAxisAlignedBoundingBox();
    EXPECT_EQ(bounds.GetMinBound(), Eigen::Vector3d(-1, 0, 0));
    EXPECT_NEAR(bounds.GetMaxBound().x(), 1.0001, 1e-6);
    EXPECT_EQ(cloud.Crop(bounds), cloud);
}

TEST(PointCloudSelect, OrientedBoxRotatesItsTest) {
    // A 10 x 1 x 1 box rotated 45 degrees about z: (3, 3, 0) lies along its long axis
    // (distance 4.24 < 5), (3, -3, 0) across it (4.24 > 0.5), both inside an axis-aligned
    // box of the same edges.
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const OrientedBoundingBox box(Eigen::Vector3d::Zero(), R, Eigen::Vector3d(10, 1, 1));
    EXPECT_TRUE(box.Contains(Eigen::Vector3d(3, 3, 0)));
    EXPECT_FALSE(box.Contains(Eigen::Vector3d(3, -3, 0)));
    EXPECT_FALSE(box.Contains(Eigen::Vector3d(3, 3, 0.51)));
    const PointCloud cloud = MakeSplats(2000, true);
    const PointCloud inside = cloud.Crop(box);
    int64_t k = 0;
    for (int64_t i = 0; i < cloud.NumPoints(); ++i) {
        // The same test written out: the point in the box's frame, against half the edges.
        const Eigen::Vector3d local = R.transpose() * Position(cloud, i);
        if (std::abs(local.x()) <= 5.0 && std::abs(local.y()) <= 0.5 &&
            std::abs(local.z()) <= 0.5) {
            ExpectRowEqual(inside, k++, cloud, i);
        }
    }
    EXPECT_EQ(inside.NumPoints(), k);
    EXPECT_GT(k, 10);  // the box holds some of the 2,000 random points
    EXPECT_EQ(cloud.Crop(box, true).NumPoints(), cloud.NumPoints() - k);
}

TEST(PointCloudSelect, BoxesRefuseWhatIsNotABox) {
    EXPECT_THROW(AxisAlignedBoundingBox(Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(1, 0, 1)),
                 core::Open3DError);  // min above max on y
    EXPECT_THROW(AxisAlignedBoundingBox(Eigen::Vector3d(0, 0, NAN), Eigen::Vector3d(1, 1, 1)),
                 core::Open3DError);
    Eigen::Matrix3d mirror = Eigen::Matrix3d::Identity();
    mirror(0, 0) = -1;
    EXPECT_THROW(OrientedBoundingBox(Eigen::Vector3d::Zero(), mirror, Eigen::Vector3d::Ones()),
                 core::Open3DError);  // determinant -1
    EXPECT_THROW(OrientedBoundingBox(Eigen::Vector3d::Zero(), 2 * Eigen::Matrix3d::Identity(),
                                     Eigen::Vector3d::Ones()),
                 core::Open3DError);  // not orthonormal
    EXPECT_THROW(OrientedBoundingBox(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(),
                                     Eigen::Vector3d(1, -1, 1)),
                 core::Open3DError);  // a negative edge
}

// Formats that encode each splat on its own: an edit commutes with writing and reading them,
// bit for bit. The others quantise against statistics of the whole cloud (compressed PLY: the
// bounds of chunks of 256 splats; SOG: codebooks and bounds of all splats), so an edited
// cloud's splats come back encoded against its own statistics (docs/editing.md).
TEST(PointCloudSelect, EditsCommuteWithEveryPerSplatFormat) {
    const PointCloud cloud = MakeSplats(700, false);
    const AxisAlignedBoundingBox box(Eigen::Vector3d(-2.5, -5, -5), Eigen::Vector3d(3.5, 5, 5));
    const std::string dir = tests::TempDir();
    for (const std::string ext : {".ply", ".splat", ".spz", ".glb", ".gltf"}) {
        SCOPED_TRACE(ext);
        io::WritePointCloud(dir + "/whole" + ext, cloud);
        io::WritePointCloud(dir + "/cropped" + ext, cloud.Crop(box));
        const PointCloud whole = Read(dir + "/whole" + ext);
        const PointCloud cropped = Read(dir + "/cropped" + ext);
        // The crop of what the format gave back is what the format gives back of the crop.
        const PointCloud want = whole.Crop(box);
        ASSERT_EQ(cropped.NumPoints(), want.NumPoints());
        EXPECT_GT(want.NumPoints(), 100);
        for (int64_t i = 0; i < want.NumPoints(); ++i) ExpectRowEqual(cropped, i, want, i);
        // And removing rows as well.
        io::WritePointCloud(dir + "/removed" + ext, cloud.RemoveByIndex({0, 5, 699}));
        EXPECT_EQ(Read(dir + "/removed" + ext), whole.RemoveByIndex({0, 5, 699}));
    }
}

}  // namespace
}  // namespace geometry
}  // namespace t
}  // namespace open3d
