#include "open3d/core/Tensor.h"

#include <gtest/gtest.h>

#include "open3d/core/Exception.h"

namespace open3d {
namespace core {

TEST(Tensor, ShapeAndZeroInit) {
    Tensor t({4, 3}, Dtype::Float32);
    EXPECT_EQ(t.NumElements(), 12);
    EXPECT_EQ(t.NumBytes(), 48);
    for (int i = 0; i < 12; ++i) EXPECT_EQ(t.Data<float>()[i], 0.0f);
    Tensor u({2, 5}, Dtype::UInt8);
    EXPECT_EQ(u.NumBytes(), 10);
    Tensor w({2, 5}, Dtype::UInt16);  // normalised depth
    EXPECT_EQ(w.NumBytes(), 20);
    EXPECT_EQ(DtypeName(Dtype::UInt16), "UInt16");
    EXPECT_EQ(w.Data<uint16_t>()[9], 0);
    EXPECT_THROW(w.Data<uint8_t>(), Open3DError);
}

TEST(Tensor, DtypeMismatchThrows) {
    Tensor t({2}, Dtype::UInt8);
    EXPECT_THROW(t.Data<float>(), Open3DError);
    EXPECT_NO_THROW(t.Data<uint8_t>());
}

TEST(Tensor, FromVectorAndEquality) {
    Tensor a = Tensor::FromVector<float>({1, 2, 3, 4, 5, 6}, {2, 3});
    Tensor b = a.Reshape({3, 2});
    EXPECT_EQ(b.Data<float>()[5], 6.0f);
    EXPECT_NE(a, b);  // same bytes, different shape
    EXPECT_EQ(a, b.Reshape({2, 3}));
    EXPECT_THROW(Tensor::FromVector<float>({1, 2}, {3}), Open3DError);
    EXPECT_THROW(a.Reshape({4}), Open3DError);
    EXPECT_THROW(Tensor({-1, 3}, Dtype::Float32), Open3DError);
}

}  // namespace core
}  // namespace open3d
