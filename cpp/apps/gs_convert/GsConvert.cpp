// gs-convert: converts a Gaussian splat scene between file formats. The input format is
// detected from the content, the output format follows the output's extension
// (docs/formats.md lists both sides and what each format loses).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

#include "open3d/core/Exception.h"
#include "open3d/core/Progress.h"
#include "open3d/core/Timer.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/OutputFiles.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/t/io/SplatHierarchyIO.h"
#include "open3d/t/io/SplatPageFile.h"

namespace {

// A one-line bar on stderr for the stages the readers and writers report
// (core::ReportProgress): drawn only on a terminal, only once the conversion has taken 0.3 s
// (small files show none), at most ten times a second, and erased when done.
class ProgressBar {
public:
    void Update(const char* stage, double fraction) {
        const double ms = open3d::core::MillisecondsSince(start_);
        if (ms < 300.0) return;
        if (stage_ == stage && ms - drawn_ms_ < 100.0 && fraction < 1.0) return;
        stage_ = stage;
        drawn_ms_ = ms;
        constexpr int kWidth = 30;
        const int filled = static_cast<int>(fraction * kWidth + 0.5);
        std::fprintf(stderr, "\r%-12s [%s%s] %3d%%  %.1f s", stage,
                     std::string(filled, '#').c_str(), std::string(kWidth - filled, '.').c_str(),
                     static_cast<int>(fraction * 100.0), ms / 1000.0);
        std::fflush(stderr);
        shown_ = true;
    }
    /// Erases the bar (before a line of output; the next update draws it again).
    void Clear() {
        if (shown_) std::fprintf(stderr, "\r%70s\r", "");
        shown_ = false;
        stage_.clear();
    }
    ~ProgressBar() { Clear(); }

private:
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
    std::string stage_;
    double drawn_ms_ = 0.0;
    bool shown_ = false;
};

}  // namespace

int main(int argc, char** argv) {
    using namespace open3d;
    std::string input, output;
    bool drop_non_finite = false, force = false, no_progress = false, lod = false, pages = false;
    int64_t page_capacity = 65536;
    CLI::App app{
        "gs-convert: converts a Gaussian splat scene between file formats.\n"
        "Reads .ply, .compressed.ply, .splat, .spz, .sog (or a SOG folder / its meta.json),\n"
        ".gltf, .glb and .ksplat, detected by content; writes the format the output's\n"
        "extension names: .ply, .compressed.ply, .splat, .spz, .sog, .glb, .gltf.\n"
        "Lossy targets (.splat, .spz, .compressed.ply, .sog) quantise the attributes;\n"
        "docs/formats.md gives the error of each.",
        "gs-convert"};
    app.add_option("input", input, "Scene to read")->required();
    app.add_option("output", output,
                   "File to write; its extension chooses the format. Its folder must exist; the "
                   "file appears only once it is complete")
        ->required();
    app.add_flag("--drop-non-finite", drop_non_finite,
                 "Drop splats with NaN or Inf values instead of refusing the file");
    app.add_flag("-f,--force", force,
                 "Overwrite the output (and its .lod and .gspages) if it exists; never the "
                 "input");
    app.add_flag("--lod", lod,
                 "Also build the level-of-detail hierarchy (docs/lod.md) and write it beside "
                 "the output as <output>.lod");
    app.add_flag("--pages", pages,
                 "Also write the scene and its hierarchy as a paged file for streaming "
                 "(docs/streaming.md) beside the output as <output>.gspages");
    app.add_option("--page-capacity", page_capacity, "--pages: nodes per page")
        ->check(CLI::Range(int64_t(8), int64_t(1) << 30))
        ->capture_default_str();
    app.add_flag("--no-progress", no_progress,
                 "No progress bar (drawn on a terminal for conversions longer than 0.3 s: "
                 "reading, decoding, clustering and compressing as they happen)");
    CLI11_PARSE(app, argc, argv);
    try {
        // The output is checked before the input is read: a bad extension or folder fails
        // at once, not after a large scene has been decoded.
        t::io::PointCloudFileFormatForWriting(output);
        t::io::CheckOutputPath("output", output);
        const std::string lod_path = output + ".lod", pages_path = output + ".gspages";
        std::vector<std::string> outputs = {output};
        if (lod) outputs.push_back(lod_path);
        if (pages) outputs.push_back(pages_path);
        std::error_code ec;
        for (const std::string& path : outputs) {
            t::io::CheckOutputIsNotAnInput(path == output ? "output" : "the output beside it", path,
                                           {{"input", input}});
            if (!force && std::filesystem::exists(path, ec)) {
                core::ThrowError("'{}' exists; pass --force to overwrite it", path);
            }
        }
        const auto start = std::chrono::steady_clock::now();
        std::optional<ProgressBar> bar;
        std::optional<core::ScopedProgressCallback> progress;
        if (!no_progress && ::isatty(STDERR_FILENO)) {
            bar.emplace();
            progress.emplace([&bar](const char* stage, double f) { bar->Update(stage, f); });
        }
        t::geometry::PointCloud cloud;
        t::io::ReadPointCloudOptions options;
        options.drop_non_finite = drop_non_finite;
        const t::io::PointCloudFileFormat format = t::io::DetectPointCloudFileFormat(input);
        const auto report = t::io::ReadPointCloud(input, cloud, options);
        if (bar) bar->Clear();
        std::printf("read %s (%s): %lld splats, SH degree %d\n", input.c_str(),
                    t::io::PointCloudFileFormatName(format),
                    static_cast<long long>(report.num_points),
                    cloud.IsGaussianSplat() ? cloud.GetGaussianSplatArrays().sh_degree : 0);
        if ((lod || pages) && !cloud.IsGaussianSplat()) {
            core::ThrowError("{}: '{}' holds points without Gaussian attributes",
                             lod ? "--lod" : "--pages", input);
        }
        // Written beside the output and renamed when complete: a failed write leaves no
        // partial file, and error messages name the output, not the temporary.
        t::io::OutputFileSet files;
        std::string written_output;
        files.Write(output, [&](const std::string& path) {
            written_output = path;
            t::io::WritePointCloud(path, cloud);
        });
        int64_t lod_nodes = 0;
        std::optional<t::geometry::SplatHierarchy> lod_hierarchy;
        bool lod_read_back_equal = false;  // the output holds exactly the splats read
        if (lod) {
            // The .lod's leaves are the output's splats as a reader will see them: a lossy or
            // reordering format's differ from the input's, and the hierarchy's fingerprint
            // must be theirs (gs-render refuses a hierarchy of another scene).
            t::geometry::PointCloud as_written;
            t::io::ReadPointCloud(written_output, as_written);
            lod_hierarchy = t::geometry::BuildSplatHierarchy(as_written);
            lod_read_back_equal = as_written == cloud;
            files.Write(lod_path, [&](const std::string& path) {
                t::io::WriteSplatHierarchy(path, *lod_hierarchy);
            });
            lod_nodes = lod_hierarchy->NumInner();
        }
        if (pages) {
            // The paged file holds its leaves itself: built from the cloud as read, which a
            // lossless output leaves as it was (the .lod's hierarchy then serves both).
            const t::geometry::SplatHierarchy hierarchy =
                lod_read_back_equal ? std::move(*lod_hierarchy)
                                    : t::geometry::BuildSplatHierarchy(cloud);
            files.Write(pages_path, [&](const std::string& path) {
                t::io::WriteSplatPages(path, cloud, hierarchy, page_capacity);
            });
        }
        files.Commit();
        progress.reset();
        bar.reset();  // erases the line before the summary
        std::printf("wrote %s (%llu bytes) in %.0f ms\n", output.c_str(),
                    static_cast<unsigned long long>(std::filesystem::file_size(output)),
                    core::MillisecondsSince(start));
        if (lod) {
            std::printf("wrote %s (%lld inner nodes over %lld splats)\n", lod_path.c_str(),
                        static_cast<long long>(lod_nodes),
                        static_cast<long long>(report.num_points));
        }
        if (pages) {
            const t::io::SplatPageFile paged(pages_path);
            std::printf("wrote %s (%lld nodes in %lld pages of up to %lld, %llu bytes)\n",
                        pages_path.c_str(), static_cast<long long>(paged.NumNodes()),
                        static_cast<long long>(paged.NumPages()),
                        static_cast<long long>(page_capacity),
                        static_cast<unsigned long long>(paged.FileBytes()));
        }
    } catch (const core::Open3DError& e) {
        std::fprintf(stderr, "gs-convert: error: %s\n", e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr,
                     "gs-convert: error: out of memory (std::bad_alloc) while converting '%s': "
                     "it needs more host memory than this machine gives (docs/memory.md)\n",
                     input.c_str());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "gs-convert: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
