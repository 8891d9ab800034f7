// Write -> read round trips: exact for PLY, within stated quantisation bounds for .splat.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <random>

#include "RandomSplatCloud.h"
#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/Progress.h"
#include "open3d/t/geometry/SphericalHarmonics.h"
#include "open3d/t/io/FileFormats.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using core::Tensor;
using geometry::PointCloud;

// What a progress callback sees (gs-convert's bar): per stage, fractions that never go back
// and end at 1. The values read or written are those of a run without a callback.
struct ProgressLog {
    std::vector<std::pair<std::string, double>> reports;
    /// Runs `work` with this log as the thread's progress callback.
    void Watch(const std::function<void()>& work) {
        const core::ScopedProgressCallback installed(
            [this](const char* stage, double f) { reports.emplace_back(stage, f); });
        work();
    }
    void ExpectStage(const std::string& stage) const {
        double last = -1.0;
        int seen = 0;
        for (const auto& [name, f] : reports) {
            if (name != stage) continue;
            EXPECT_GE(f, last) << stage;
            last = f;
            ++seen;
        }
        EXPECT_GT(seen, 2) << stage << " was reported " << seen << " times";
        EXPECT_EQ(last, 1.0) << stage;
    }
};

TEST(RoundTrip, LargeFilesReportProgress) {
    const std::string dir = tests::TempDir();
    // 320k splats of SH 0: an 18 MB PLY, above the 16 MiB from which reading is reported in
    // blocks and the 2^18 vertices from which decoding is.
    const PointCloud large = RandomCloud(320000, 0, 21);
    WritePointCloud(dir + "/large.ply", large);
    PointCloud quiet, watched;
    ReadPointCloud(dir + "/large.ply", quiet);
    ProgressLog log;
    log.Watch([&] { ReadPointCloud(dir + "/large.ply", watched); });
    log.ExpectStage("reading");
    log.ExpectStage("decoding");
    EXPECT_TRUE(watched == quiet);
    // SOG: more distinct SH vectors than a palette holds are clustered, then every image is
    // compressed; the file equals one written without a callback.
    const PointCloud sh = RandomCloud(70000, 1, 22);
    WritePointCloud(dir + "/quiet.sog", sh);
    ProgressLog sog;
    sog.Watch([&] { WritePointCloud(dir + "/watched.sog", sh); });
    sog.ExpectStage("clustering");
    sog.ExpectStage("compressing");
    EXPECT_EQ(tests::ReadFileBytes(dir + "/watched.sog"), tests::ReadFileBytes(dir + "/quiet.sog"));
    // Outside a scope nothing is called.
    const size_t before = sog.reports.size();
    WritePointCloud(dir + "/again.sog", sh);
    EXPECT_EQ(sog.reports.size(), before);
}

TEST(RoundTrip, PlyIsExactInEveryEncoding) {
    const std::string dir = tests::TempDir();
    for (int degree = 0; degree <= 3; ++degree) {
        const PointCloud original = RandomCloud(257, degree, 11 + degree);
        for (PlyFormat format :
             {PlyFormat::BinaryLittleEndian, PlyFormat::BinaryBigEndian, PlyFormat::Ascii}) {
            const std::string path = dir + "/rt.ply";
            WritePointCloudOptions options;
            options.ply_format = format;
            WritePointCloud(path, original, options);
            PointCloud back;
            ReadPointCloud(path, back);
            // Re-reading normalises quaternions; unit ones are kept bit-exact by design.
            EXPECT_TRUE(back == original) << "degree " << degree << " format " << int(format);
        }
    }
}

TEST(RoundTrip, LogScaleEncodingIsExactWherePossible) {
    // Every float log-scale l in [-20, 20] sampled: exp then log gives back a value with the
    // same exp, i.e. the cloud round trip is exact even where log itself is not invertible.
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> dist(-20.0f, 20.0f);
    for (int i = 0; i < 200000; ++i) {
        const float scale = DecodeLogScale(dist(rng));
        ASSERT_EQ(DecodeLogScale(EncodeLogScale(scale)), scale);
    }
    EXPECT_EQ(DecodeLogScale(EncodeLogScale(0.0f)), 0.0f);
    // Arbitrary scales (not from a log) come back within the log's rounding: for |log s| <= 20
    // a half ulp of the log is <= 9.5e-7, so the relative error is <= ~1e-6 (measured 1.01e-6 over
    // 200k samples).
    std::uniform_real_distribution<double> any(1e-8, 1e8);
    double worst = 0;
    for (int i = 0; i < 200000; ++i) {
        const float s = static_cast<float>(any(rng));
        worst = std::max(worst, std::abs(double(DecodeLogScale(EncodeLogScale(s))) / s - 1.0));
    }
    EXPECT_LT(worst, 1.2e-6);
}

TEST(RoundTrip, SplatWithinQuantisation) {
    const std::string path = tests::TempDir() + "/rt.splat";
    const PointCloud original = RandomCloud(1000, 0, 5);
    int clamp_warnings = 0;
    auto previous = core::SetLogSink([&](core::LogLevel level, std::string_view msg) {
        if (level == core::LogLevel::Warning && msg.find("clamped") != msg.npos) ++clamp_warnings;
    });
    WritePointCloud(path, original);
    core::SetLogSink(previous);
    EXPECT_EQ(clamp_warnings, 1);  // random f_dc ~ N(0,1) leaves [0, 1] for some splats
    PointCloud back;
    ReadPointCloud(path, back);
    ASSERT_EQ(back.NumPoints(), 1000);
    EXPECT_TRUE(back.GetPointPositions() == original.GetPointPositions());  // float32: exact
    EXPECT_TRUE(back.GetPointAttr("scale") == original.GetPointAttr("scale"));
    const float* dc0 = original.GetPointAttr("f_dc").Data<float>();
    const float* dc1 = back.GetPointAttr("f_dc").Data<float>();
    const float* op0 = original.GetPointAttr("opacity").Data<float>();
    const float* op1 = back.GetPointAttr("opacity").Data<float>();
    const float* q0 = original.GetPointAttr("rot").Data<float>();
    const float* q1 = back.GetPointAttr("rot").Data<float>();
    for (int64_t i = 0; i < 1000; ++i) {
        for (int c = 0; c < 3; ++c) {
            // Colour 0.5 + C0 f_dc is stored in 8 bits: error <= 0.5/255 inside [0, 1].
            const double colour0 = std::clamp(0.5 + geometry::kSH_C0 * dc0[i * 3 + c], 0.0, 1.0);
            const double colour1 = 0.5 + geometry::kSH_C0 * dc1[i * 3 + c];
            ASSERT_LE(std::abs(colour1 - colour0), 0.5 / 255 + 1e-6) << i;
        }
        // Opacity sigmoid stored in 8 bits, with the 1e-6 margin at 0 and 255.
        const double a0 = 1 / (1 + std::exp(-double(op0[i])));
        const double a1 = 1 / (1 + std::exp(-double(op1[i])));
        ASSERT_LE(std::abs(a1 - a0), 0.5 / 255 + 1e-6) << i;
        // Each quaternion component is quantised to 1/128 before renormalising: the rotation
        // angle between q0 and q1 (2 acos|<q0, q1>|) stays small: measured max 0.0150 rad over
        // 200k random unit quaternions; tolerance 0.02 rad.
        double dot = 0;
        for (int k = 0; k < 4; ++k) dot += double(q0[i * 4 + k]) * q1[i * 4 + k];
        ASSERT_LT(2 * std::acos(std::min(1.0, std::abs(dot))), 0.02) << i;
    }
}

TEST(RoundTrip, SplatDropsShWithWarningAndIsIdempotent) {
    const std::string dir = tests::TempDir();
    int sh_warnings = 0;
    auto previous = core::SetLogSink([&](core::LogLevel level, std::string_view msg) {
        if (level == core::LogLevel::Warning && msg.find("f_rest") != msg.npos) ++sh_warnings;
    });
    WritePointCloud(dir + "/a.splat", RandomCloud(50, 2, 8));
    core::SetLogSink(previous);
    EXPECT_EQ(sh_warnings, 1);
    PointCloud once, twice;
    ReadPointCloud(dir + "/a.splat", once);
    EXPECT_EQ(once.GaussianSplatGetSHOrder(), 0);
    // A cloud read from .splat is already on the quantisation grid: bytes round trip exactly.
    WritePointCloud(dir + "/b.splat", once);
    ReadPointCloud(dir + "/b.splat", twice);
    EXPECT_TRUE(twice.GetPointAttr("f_dc") == once.GetPointAttr("f_dc"));
    EXPECT_TRUE(twice.GetPointAttr("opacity") == once.GetPointAttr("opacity"));
}

TEST(RoundTrip, SplatTruncatedRecord) {
    const std::string path = tests::TempDir() + "/cut.splat";
    WritePointCloud(path, RandomCloud(3, 0, 1));
    std::filesystem::resize_file(path, 3 * 32 - 5);
    PointCloud cloud;
    try {
        ReadPointCloud(path, cloud);
        ADD_FAILURE() << "no error";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("splat 2 is incomplete"), std::string::npos)
            << e.what();
    }
    EXPECT_TRUE(cloud.IsEmpty());
}

TEST(RoundTrip, WriterRefusesWhatItCannotStore) {
    PointCloud cloud = RandomCloud(2, 0, 1);
    cloud.GetPointAttr("scale").Data<float>()[4] = -1.0f;
    EXPECT_THROW(WritePointCloud(tests::TempDir() + "/neg.ply", cloud), core::Open3DError);
    EXPECT_THROW(WritePointCloud(tests::TempDir() + "/x.xyz", RandomCloud(2, 0, 1)),
                 core::Open3DError);
    EXPECT_THROW(WritePointCloud("/nonexistent-dir/x.ply", RandomCloud(2, 0, 1)),
                 core::Open3DError);
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
