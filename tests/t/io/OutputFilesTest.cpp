// Output files of the apps (OutputFiles.h): paths refused before any work, and outputs that
// appear whole, all together, or not at all.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/t/io/ImageIO.h"
#include "open3d/t/io/OutputFiles.h"

namespace open3d {
namespace t {
namespace io {
namespace {

namespace fs = std::filesystem;
using geometry::Image;

// The error of CheckOutputPath, or "" when it accepts the path.
std::string CheckError(const std::string& path) {
    try {
        CheckOutputPath("--out", path);
    } catch (const core::Open3DError& e) {
        return e.what();
    }
    return "";
}

size_t CountEntries(const std::string& dir) {
    return static_cast<size_t>(std::distance(fs::directory_iterator(dir), {}));
}

TEST(OutputFiles, CheckOutputPathNamesTheFlagAndTheProblem) {
    const std::string dir = tests::TempDir();
    EXPECT_EQ(CheckError(dir + "/ok.png"), "");
    EXPECT_EQ(CheckError("relative.png"), "");  // the current folder
    const std::string missing = CheckError(dir + "/no/such/folder/x.png");
    EXPECT_NE(missing.find("--out"), std::string::npos) << missing;
    EXPECT_NE(missing.find("does not exist"), std::string::npos) << missing;
    const std::string folder = CheckError(dir);
    EXPECT_NE(folder.find("is a folder"), std::string::npos) << folder;
    EXPECT_NE(CheckError("").find("empty"), std::string::npos);
    EXPECT_EQ(CountEntries(dir), 0u) << "checking must not create anything";
}

TEST(OutputFiles, ExtensionsAndSamePaths) {
    EXPECT_EQ(LowerCaseExtension("a/B.PNG"), "png");
    EXPECT_EQ(LowerCaseExtension("a.b/c"), "");
    EXPECT_TRUE(SameOutputPath("x.png", "./x.png"));
    EXPECT_TRUE(SameOutputPath("d/../x.png", "x.png"));
    EXPECT_FALSE(SameOutputPath("x.png", "y.png"));
}

TEST(OutputFiles, NothingAppearsWithoutCommit) {
    const std::string dir = tests::TempDir();
    {
        OutputFileSet files;
        const std::string a = files.Add(dir + "/a.png");
        const std::string b = files.Add(dir + "/b.npy");
        EXPECT_EQ(LowerCaseExtension(a), "png") << "the writer picks the format by extension";
        EXPECT_EQ(fs::path(a).parent_path(), fs::path(dir));
        std::ofstream(a) << "complete";
        std::ofstream(b) << "half";  // as if the second write then failed
    }
    EXPECT_EQ(CountEntries(dir), 0u) << "temporaries left behind or outputs written";
}

TEST(OutputFiles, CommitRenamesEveryOutput) {
    const std::string dir = tests::TempDir();
    std::ofstream(dir + "/a.png") << "old";
    OutputFileSet files;
    Image image(2, 2, 1, core::Dtype::Float32);
    WriteImage(files.Add(dir + "/a.npy"), image);
    EXPECT_EQ(WritePNG16(files.Add(dir + "/d.png"), image, 1000.0), 0);
    EXPECT_FALSE(fs::exists(dir + "/a.npy"));
    files.Commit();
    EXPECT_EQ(ReadNpy(dir + "/a.npy"), image);
    EXPECT_TRUE(fs::exists(dir + "/d.png"));
    EXPECT_EQ(CountEntries(dir), 3u) << "a.png, a.npy, d.png and no temporaries";
}

TEST(OutputFiles, FailedWriteLeavesNoFile) {
    const std::string dir = tests::TempDir();
    EXPECT_THROW(
        {
            OutputFileSet files;
            WriteImage(files.Add(dir + "/c.png"), Image(2, 2, 3, core::Dtype::UInt8));
            WritePNG16(files.Add(dir + "/d.png"), Image(), 1000.0);  // empty: throws
            files.Commit();
        },
        core::Open3DError);
    EXPECT_EQ(CountEntries(dir), 0u) << "the colour image of a failed set was left behind";
}

TEST(OutputFiles, WriteErrorsNameTheOutputNotTheTemporary) {
    const std::string dir = tests::TempDir();
    OutputFileSet files;
    try {
        files.Write(dir + "/o.spz", [](const std::string& temporary) {
            core::ThrowError("Cannot write '{}' ({}): No space left on device", temporary,
                             fs::path(temporary).filename().string());
        });
        ADD_FAILURE() << "the writer's error was swallowed";
    } catch (const core::Open3DError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "Cannot write '" + dir + "/o.spz' (o.spz): No space left on device");
    }
    files.Commit();
    EXPECT_EQ(CountEntries(dir), 0u);
}

TEST(OutputFiles, WriterWarningsNameTheOutputNotTheTemporary) {
    // A writer's warning ("'.tmp-PID-0-0-o.splat': .splat holds SH degree 0 only") named
    // the temporary the user never sees.
    const std::string dir = tests::TempDir();
    std::vector<std::string> messages;
    core::LogSink previous = core::SetLogSink(
        [&messages](core::LogLevel, std::string_view m) { messages.emplace_back(m); });
    OutputFileSet files;
    files.Write(dir + "/o.splat", [](const std::string& temporary) {
        core::LogWarning("'{}' ({}): SH dropped", temporary,
                         fs::path(temporary).filename().string());
        std::ofstream(temporary) << "x";
    });
    core::LogWarning("after: '{}'", "o.splat");
    core::SetLogSink(previous);
    files.Commit();
    ASSERT_EQ(messages.size(), 2u);
    EXPECT_EQ(messages[0], "'" + dir + "/o.splat' (o.splat): SH dropped");
    EXPECT_EQ(messages[1], "after: 'o.splat'");
}

TEST(OutputFiles, AnOutputThatIsAnInputIsRefused) {
    const std::string dir = tests::TempDir();
    const std::string input = dir + "/in.ply";
    std::ofstream(input) << "ply";
    fs::create_symlink(input, dir + "/link.ply");
    fs::create_hard_link(input, dir + "/hard.ply");
    const std::vector<NamedInput> inputs = {{"--cameras", ""}, {"--input", input}};
    for (const std::string& output :
         {input, dir + "/./in.ply", dir + "/link.ply", dir + "/hard.ply"}) {
        SCOPED_TRACE(output);
        try {
            CheckOutputIsNotAnInput("--out", output, inputs);
            ADD_FAILURE() << "accepted";
        } catch (const core::Open3DError& e) {
            EXPECT_NE(std::string(e.what()).find("--out '" + output + "' is the --input file"),
                      std::string::npos)
                << e.what();
        }
    }
    EXPECT_NO_THROW(CheckOutputIsNotAnInput("--out", dir + "/other.ply", inputs));
    EXPECT_NO_THROW(CheckOutputIsNotAnInput("--out", "", inputs));
}

}  // namespace
}  // namespace io
}  // namespace t
}  // namespace open3d
