// PlayCanvas's biker.compressed.ply against values computed from its bytes alone, outside
// the library (the Python in the comment below).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "IoTestHelpers.h"
#include "TestUtility.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using geometry::PointCloud;

constexpr const char* kBikerCompressed = "formats/biker.compressed.ply";

struct ExpectedSplat {
    int64_t index;
    float position[3], scale[3], rot[4], f_dc[3], opacity;
};

// Computed from the bytes alone with this Python (struct and math only), in ../shared/data:
//   f32 = lambda v: struct.unpack('<f', struct.pack('<f', v))[0]
//   d = open('formats/biker.compressed.ply', 'rb').read(); h = d.index(b'end_header\n') + 11
//   chunk = lambda c: struct.unpack_from('<18f', d, h + c * 72)
//   vert = lambda i: struct.unpack_from('<4I', d, h + 597 * 72 + i * 16)
//   un = lambda v, b: (v & ((1 << b) - 1)) / ((1 << b) - 1)
//   lerp = lambda a, b, t: a * (1 - t) + b * t
//   c = chunk(i // 256); p, r, s, col = vert(i); fields = [(21, 11), (11, 10), (0, 11)]
//   pos = [f32(lerp(c[k], c[3 + k], un(p >> sh, b))) for k, (sh, b) in enumerate(fields)]
//   scale = [f32(math.exp(f32(lerp(c[6 + k], c[9 + k], un(s >> sh, b)))))
//            for k, (sh, b) in enumerate(fields)]
//   f_dc = [f32((lerp(c[12 + k], c[15 + k], un(col >> (24 - 8 * k), 8)) - 0.5) / SH_C0)
//           for k in range(3)]
//   a = un(col, 8); opacity = f32(-math.log(1 / a - 1))
//   st = [(un(r >> sh, 10) - 0.5) * 2 ** 0.5 for sh in (20, 10, 0)]
//   rot = st[:]; rot.insert(r >> 30, math.sqrt(1 - sum(x * x for x in st)))  # (w, x, y, z)
const ExpectedSplat kBikerSplats[] = {
    {0,
     {-0.10453680157661438f, -2.3878982067108154f, -0.3608109951019287f},
     {0.0023136779200285673f, 0.014897788874804974f, 0.0008667604997754097f},
     {0.4610363841056824f, -0.06290001422166824f, 0.8848552107810974f, 0.022809896618127823f},
     {0.5478684902191162f, 0.5222843289375305f, 0.5681517720222473f},
     -2.577688455581665f},
    {1,
     {-0.10449791699647903f, -2.401226758956909f, -0.35535505414009094f},
     {0.0018251872388646007f, 0.031785935163497925f, 0.0007897504256106913f},
     {0.5370693802833557f, -0.08225386589765549f, 0.8388347029685974f, -0.033869240432977676f},
     {0.62809157371521f, 0.6290907263755798f, 0.6740944981575012f},
     -2.7725887298583984f},
    {255,
     {-0.1290137767791748f, -2.060115337371826f, -0.4440408945083618f},
     {0.004674970638006926f, 0.006069208960980177f, 0.002269479213282466f},
     {0.5025089383125305f, -0.28546929359436035f, 0.09469562768936157f, 0.8105706572532654f},
     {-1.3774865865707397f, -1.3601781129837036f, -1.3388174772262573f},
     -0.3728889524936676f},
    {256,
     {-0.13092470169067383f, -2.047135829925537f, -0.4464400112628937f},
     {0.010003495030105114f, 0.004301309119910002f, 0.00016215493087656796f},
     {0.9058474898338318f, -0.05322309210896492f, 0.38085615634918213f, 0.17764070630073547f},
     {-1.6601104736328125f, -1.65126633644104f, -1.6268891096115112f},
     -2.1756255626678467f},
    {76543,
     {0.156648188829422f, -1.3464927673339844f, -0.15543480217456818f},
     {0.0028675736393779516f, 0.0007153447950258851f, 0.002899527782574296f},
     {0.9859962463378906f, -0.08778353780508041f, -0.138933002948761f, -0.02833956852555275f},
     {-0.8893909454345703f, -0.8419008851051331f, -0.8761141300201416f},
     -3.4299468994140625f},
    {152745,
     {0.16716530919075012f, -0.6030639410018921f, 0.3288194239139557f},
     {0.0031036201398819685f, 0.007889961823821068f, 0.0004816018044948578f},
     {0.9981916546821594f, 0.040781330317258835f, -0.042163748294115067f, 0.013132970780134201f},
     {1.1197552680969238f, 1.0974349975585938f, 1.0597506761550903f},
     -2.8457396030426025f},
};

TEST(CompressedPly, SharedFileMatchesIndependentValues) {
    OPEN3D_REQUIRE_DATA(kBikerCompressed);
    const std::string path = tests::DataPath(kBikerCompressed);
    EXPECT_EQ(DetectPointCloudFileFormat(path), PointCloudFileFormat::kCompressedPly);
    PointCloud cloud;
    const ReadPointCloudReport report = ReadPointCloud(path, cloud);
    ASSERT_EQ(cloud.NumPoints(), 152746);
    EXPECT_EQ(cloud.GaussianSplatGetSHOrder(), 0);
    EXPECT_EQ(report.trailing_bytes, 0);
    EXPECT_EQ(report.dropped_non_finite, 0);
    for (const ExpectedSplat& e : kBikerSplats) {
        SCOPED_TRACE("splat " + std::to_string(e.index));
        const int64_t i = e.index;
        for (int c = 0; c < 3; ++c) {
            EXPECT_FLOAT_EQ(FloatsOf(cloud, "positions")[i * 3 + c], e.position[c]);
            EXPECT_FLOAT_EQ(FloatsOf(cloud, "scale")[i * 3 + c], e.scale[c]);
            EXPECT_FLOAT_EQ(FloatsOf(cloud, "f_dc")[i * 3 + c], e.f_dc[c]);
        }
        for (int c = 0; c < 4; ++c) EXPECT_FLOAT_EQ(FloatsOf(cloud, "rot")[i * 4 + c], e.rot[c]);
        EXPECT_FLOAT_EQ(FloatsOf(cloud, "opacity")[i], e.opacity);
    }
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
