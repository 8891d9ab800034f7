// Reads a splat file of any format (t::io::ReadPointCloud) on a worker thread, so the viewer
// keeps drawing and taking input while a large scene loads, and describes the read for the
// panel ("Loading biker.spz (12.3 MB), 2.4 s"). The readers report no fraction done, so the
// progress shown is the file's size and the time so far.
//
//   reader.Start(path);                        // returns at once
//   if (auto cloud = reader.TakeResult()) ...  // on the loop's thread, once it is done
#pragma once

#include <chrono>
#include <future>
#include <optional>
#include <string>

#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace visualization {

class BackgroundCloudReader {
public:
    BackgroundCloudReader() = default;
    /// Waits for a read still running (its result is dropped).
    ~BackgroundCloudReader();
    BackgroundCloudReader(const BackgroundCloudReader&) = delete;
    BackgroundCloudReader& operator=(const BackgroundCloudReader&) = delete;

    /// Starts reading `path`; the cloud must have the Gaussian splat attributes
    /// (t::io::RequireGaussianSplat). Throws core::Open3DError while another read runs.
    void Start(const std::string& path);
    /// True from Start until TakeResult returned or threw.
    bool IsBusy() const { return future_.valid(); }
    /// The path of the current (or last) read.
    const std::string& GetPath() const { return path_; }
    /// The cloud once the read is done (then the reader is free again); nothing while it
    /// runs or when none was started. Rethrows the reader's error (core::Open3DError naming
    /// the file).
    std::optional<t::geometry::PointCloud> TakeResult();
    /// "Loading NAME (SIZE MB), T s" while busy; empty otherwise.
    std::string Describe() const;

private:
    std::string path_;
    double size_mb_ = 0.0;
    std::chrono::steady_clock::time_point start_;
    std::future<t::geometry::PointCloud> future_;
};

}  // namespace visualization
}  // namespace open3d
