#include "CameraPathRender.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "open3d/camera/CameraPath.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/core/Timer.h"
#include "open3d/t/io/H264VideoWriter.h"
#include "open3d/t/io/ImageIO.h"
#include "open3d/t/io/OutputFiles.h"

namespace gs_render {

namespace {

using namespace open3d;
namespace rendering = open3d::visualization::rendering;

// <stem>_<index, 5 digits>.png beside the given .png.
std::string FramePath(const std::string& output, size_t index) {
    const std::string stem = output.substr(0, output.size() - 4);  // ".png"
    char number[32];
    std::snprintf(number, sizeof(number), "_%05zu.png", index);
    return stem + number;
}

// Writes rendered batches on a thread of its own, so the device renders the next batch while
// this one is encoded or compressed: at most two batches wait. An error on the writer's
// thread is thrown again by the next Push or by Finish; the destructor drops what still waits
// (an error on the rendering side) and stops the thread.
class BatchWriter {
public:
    using Write = std::function<void(size_t first_frame, std::vector<rendering::RenderOutput>&)>;
    explicit BatchWriter(Write write) : write_(std::move(write)), thread_([this] { Run(); }) {}
    ~BatchWriter() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            queue_.clear();
            closed_ = true;
        }
        changed_.notify_all();
        thread_.join();
    }
    void Push(size_t first_frame, std::vector<rendering::RenderOutput> outputs) {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return queue_.size() < 2 || error_; });
        if (error_) std::rethrow_exception(error_);
        queue_.emplace_back(first_frame, std::move(outputs));
        changed_.notify_all();
    }
    /// Waits until every pushed batch is written.
    void Finish() {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return (queue_.empty() && !busy_) || error_; });
        if (error_) std::rethrow_exception(error_);
    }
    size_t Written() const { return written_; }

private:
    void Run() {
        std::unique_lock<std::mutex> lock(mutex_);
        while (true) {
            changed_.wait(lock, [&] { return !queue_.empty() || closed_; });
            if (queue_.empty()) return;  // closed
            auto [first, outputs] = std::move(queue_.front());
            queue_.pop_front();
            busy_ = true;
            lock.unlock();
            try {
                write_(first, outputs);
                written_ += outputs.size();
            } catch (...) {
                lock.lock();
                error_ = std::current_exception();
                busy_ = false;
                changed_.notify_all();
                return;
            }
            lock.lock();
            busy_ = false;
            changed_.notify_all();
        }
    }

    Write write_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<std::pair<size_t, std::vector<rendering::RenderOutput>>> queue_;
    bool busy_ = false, closed_ = false;
    std::exception_ptr error_;
    std::atomic<size_t> written_{0};
    std::thread thread_;  // last: started once the members above exist
};

}  // namespace

void CheckCameraPathOutput(const CameraPathOptions& options) {
    t::io::CheckOutputPath("-o/--output", options.output);
    const std::string ext = t::io::LowerCaseExtension(options.output);
    if (ext != "png" && ext != "mp4") {
        core::ThrowError(
            "-o/--output '{}': with --camera-path use .png (a sequence of frames beside it, "
            "<name>_00000.png, ...) or .mp4 (an H.264 video)",
            options.output);
    }
    if (ext == "mp4") {
        t::io::H264VideoOptions video;
        video.preset = options.preset;
        video.crf = options.crf;
        t::io::CheckH264VideoOptions(video);
    }
}

size_t RenderCameraPath(const CameraPathOptions& options, rendering::GaussianSplatBackend& backend,
                        const rendering::RenderConfig& config) {
    const camera::CameraPath path = camera::CameraPath::FromViews(
        camera::ReadCamerasJson(options.path_file), options.seconds_per_keyframe);
    std::vector<camera::PinholeCamera> frames = path.Frames(options.fps);
    // The keyframes share one size, so every frame gets the same one.
    for (camera::PinholeCamera& c : frames) {
        c = c.ResizedKeepingAspect(options.width, options.height);
    }
    const int w = frames.front().width, h = frames.front().height;
    const bool video = t::io::LowerCaseExtension(options.output) == "mp4";
    std::printf("camera path: %zu keyframes over %.3f s, %zu frames at %g fps, %dx%d -> %s\n",
                path.GetKeyframes().size(), path.GetDuration(), frames.size(), options.fps, w, h,
                video ? options.output.c_str() : FramePath(options.output, 0).c_str());
    std::fflush(stdout);

    std::unique_ptr<t::io::H264VideoWriter> writer;
    if (video) {
        t::io::H264VideoOptions video_options;
        video_options.preset = options.preset;
        video_options.crf = options.crf;
        writer = std::make_unique<t::io::H264VideoWriter>(options.output, w, h, options.fps,
                                                          video_options);
    }
    BatchWriter output([&](size_t first, std::vector<rendering::RenderOutput>& outputs) {
        if (video) {
            for (const rendering::RenderOutput& out : outputs)
                writer->WriteFrame(out.color.Data<uint8_t>(), 4);
            return;
        }
        // A batch's PNGs compress in parallel: zlib on one thread wrote 2.4 1080p frames a
        // second on the H100's host, a fifteenth of what the device renders.
        core::ParallelFor(
            int64_t(outputs.size()),
            [&](int64_t k) {
                const t::geometry::Image color = outputs[k].color.SelectChannels(0, 3);
                t::io::OutputFileSet files;
                files.Write(FramePath(options.output, first + size_t(k)),
                            [&](const std::string& p) { t::io::WriteImage(p, color); });
                files.Commit();
            },
            1);
    });
    const auto start = std::chrono::steady_clock::now();
    double last_report = -1.0;
    const auto report = [&](bool last) {
        const double seconds = core::MillisecondsSince(start) / 1000.0;
        if (!last && seconds - last_report < 1.0) return;
        last_report = seconds;
        const size_t done = output.Written();
        std::printf("frame %zu/%zu (%.0f%%), %.1f frames/s\n", done, frames.size(),
                    100.0 * double(done) / double(frames.size()),
                    double(done) / std::max(seconds, 1e-9));
        std::fflush(stdout);
    };
    const size_t batch = size_t(std::max(1, options.batch));
    for (size_t begin = 0; begin < frames.size(); begin += batch) {
        const size_t end = std::min(frames.size(), begin + batch);
        const std::vector<camera::PinholeCamera> views(frames.begin() + begin,
                                                       frames.begin() + end);
        // PNG frames: float colour converted by the same WriteImage as a single render's PNG,
        // so a frame at a keyframe is that view's gs-render image byte for byte. Video: 8-bit
        // colour from the device (a quarter of the bytes to read back).
        rendering::BatchOptions batch_options;
        batch_options.color_uint8 = video;
        output.Push(begin, backend.RenderBatch(views, config, batch_options));
        report(false);
    }
    output.Finish();
    report(true);
    if (video) {
        writer->Finish();
        std::printf("wrote %s (H.264, %dx%d, CRF %g, x264 preset %s)\n", options.output.c_str(),
                    writer->CodedWidth(), writer->CodedHeight(), options.crf,
                    options.preset.c_str());
    } else {
        std::printf("wrote %s .. %s\n", FramePath(options.output, 0).c_str(),
                    FramePath(options.output, frames.size() - 1).c_str());
    }
    return frames.size();
}

}  // namespace gs_render
