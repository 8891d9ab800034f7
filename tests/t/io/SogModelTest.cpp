// meta.json's "model" (splat-transform 3.2: "antialiased", "2dgs") and "antialias" in SOG
// versions 1 and 2: an antialiased scene is read with a warning to render it with
// antialiasing on, 2D Gaussian splats are refused, an unknown model is read with a warning.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "SogV1TestFiles.h"
#include "TestUtility.h"
#include "open3d/core/Logging.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using geometry::PointCloud;
using namespace sogv1;

// meta.json's "model" and "antialias" act the same in version 1 and in version 2 (a file of
// this library's writer with its meta.json edited).
TEST(SogModel, AntialiasedWarnsTwoDgsIsRefusedUnknownWarns) {
    const std::string dir = tests::TempDir();
    const V1Sog v1 = Encode(RandomTruth(20, 0, 0, 8), 5, 4);
    const PointCloud cloud = Read(Write(v1, dir + "/plain_v1.sog"));
    WritePointCloud(dir + "/plain_v2.sog", cloud);
    const PointCloud cloud_v2 = Read(dir + "/plain_v2.sog");
    std::vector<std::pair<std::string, std::vector<uint8_t>>> v2_entries;
    {
        std::ifstream in(dir + "/plain_v2.sog", std::ios::binary);
        const std::vector<uint8_t> bytes(std::istreambuf_iterator<char>(in), {});
        const ZipReader zip(bytes.data(), bytes.size(), "plain_v2.sog");
        for (const std::string& name : zip.Names()) v2_entries.emplace_back(name, zip.Read(name));
    }
    int k = 0;
    // The v1 and the v2 file with `edit` applied to meta.json.
    const auto both = [&](const std::function<void(Json&)>& edit) {
        V1Sog sog = v1;
        edit(sog.meta);
        const std::string n = std::to_string(k++);
        std::vector<std::string> paths{Write(sog, dir + "/v1_" + n + ".sog")};
        ZipWriter zip;
        for (auto [name, bytes] : v2_entries) {
            if (name == "meta.json") {
                Json m = Json::parse(bytes.begin(), bytes.end());
                EXPECT_EQ(m["version"], 2);
                edit(m);
                const std::string text = m.dump();
                bytes.assign(text.begin(), text.end());
            }
            zip.Add(name, bytes);
        }
        paths.push_back(dir + "/v2_" + n + ".sog");
        WriteFileBytes(paths.back(), zip.Finish());
        return paths;
    };
    const auto read_warnings = [&](const std::string& path) {
        PointCloud c;
        const std::vector<std::string> w = tests::CaptureWarnings([&] { ReadPointCloud(path, c); });
        // The flags change nothing in what is read.
        EXPECT_TRUE(c == (path.find("/v2_") != std::string::npos ? cloud_v2 : cloud)) << path;
        return w;
    };
    for (const std::string& path : both([](Json& m) { m["model"] = "default"; })) {
        EXPECT_TRUE(read_warnings(path).empty()) << path;
    }
    for (const std::string& path : both([](Json& m) { m["antialias"] = false; })) {
        EXPECT_TRUE(read_warnings(path).empty()) << path;
    }
    // Antialiased, by either field or both: read, with one warning to render with
    // antialiasing on (the SPZ reader's wording for its flag).
    for (const auto& edit : std::vector<std::function<void(Json&)>>{
             [](Json& m) { m["model"] = "antialiased"; }, [](Json& m) { m["antialias"] = true; },
             [](Json& m) {
                 m["model"] = "antialiased";
                 m["antialias"] = true;
             }}) {
        for (const std::string& path : both(edit)) {
            const std::vector<std::string> w = read_warnings(path);
            ASSERT_EQ(w.size(), 1u) << path;
            EXPECT_NE(w[0].find(path), std::string::npos) << w[0];
            EXPECT_NE(w[0].find("render it with antialiasing on"), std::string::npos) << w[0];
        }
    }
    // 2D Gaussian splats: refused, naming the file, the field and the value.
    for (const std::string& path : both([](Json& m) {
             m["model"] = "2dgs";
             m["antialias"] = true;
         })) {
        ExpectError(path, {"'model' is '2dgs'", "cannot draw them faithfully"});
    }
    // An unknown model: read as ordinary 3D Gaussians, with a warning naming it.
    for (const std::string& path : both([](Json& m) { m["model"] = "3dgut"; })) {
        const std::vector<std::string> w = read_warnings(path);
        ASSERT_EQ(w.size(), 1u) << path;
        EXPECT_NE(w[0].find("'3dgut'"), std::string::npos) << w[0];
        EXPECT_NE(w[0].find("read as ordinary 3D Gaussians"), std::string::npos) << w[0];
    }
    // Values of the wrong type are errors, not guesses.
    for (const std::string& path : both([](Json& m) { m["model"] = 2; })) {
        ExpectError(path, {"'model' is 2, expected a string"});
    }
    for (const std::string& path : both([](Json& m) { m["antialias"] = "yes"; })) {
        ExpectError(path, {"'antialias' is \"yes\", expected true or false"});
    }
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
