#include "CameraPathRender.h"

#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include "open3d/camera/CameraPath.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Timer.h"
#include "open3d/t/io/ImageIO.h"
#include "open3d/t/io/OutputFiles.h"

extern char** environ;

namespace gs_render {

namespace {

using namespace open3d;
namespace rendering = open3d::visualization::rendering;

// The first executable `name` on PATH, or "" when none.
std::string FindProgram(const std::string& name) {
    const char* path = std::getenv("PATH");
    std::string dirs = path ? path : "";
    size_t begin = 0;
    while (begin <= dirs.size()) {
        const size_t end = std::min(dirs.find(':', begin), dirs.size());
        const std::string dir = dirs.substr(begin, end - begin);
        const std::string candidate = (dir.empty() ? "." : dir) + "/" + name;
        if (::access(candidate.c_str(), X_OK) == 0) return candidate;
        begin = end + 1;
    }
    return "";
}

// <stem>_<index, 5 digits>.png beside the given .png.
std::string FramePath(const std::string& output, size_t index) {
    const std::string stem = output.substr(0, output.size() - 4);  // ".png"
    char number[32];
    std::snprintf(number, sizeof(number), "_%05zu.png", index);
    return stem + number;
}

// ffmpeg reading raw RGB frames from a pipe and writing H.264 to `path` (no shell: the path is
// one argument however it is spelt).
class FfmpegWriter {
public:
    FfmpegWriter(const std::string& program, const std::string& path, int width, int height,
                 double fps)
        : path_(path) {
        // A write to a pipe ffmpeg has closed fails (EPIPE) instead of killing this process.
        std::signal(SIGPIPE, SIG_IGN);
        int fds[2];
        if (::pipe(fds) != 0)
            core::ThrowError("cannot make a pipe for ffmpeg: {}", std::strerror(errno));
        const std::vector<std::string> args = {
            program, "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24",
            "-video_size", std::to_string(width) + "x" + std::to_string(height), "-framerate",
            fmt::format("{}", fps), "-i", "-",
            // yuv420p wants even sizes: an odd one gets a row or column of padding.
            "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-preset", "veryfast",
            "-pix_fmt", "yuv420p", "-movflags", "+faststart", "-f", "mp4", path};
        std::vector<char*> argv;
        for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
        posix_spawn_file_actions_addclose(&actions, fds[1]);
        const int failed =
            posix_spawn(&pid_, program.c_str(), &actions, nullptr, argv.data(), environ);
        posix_spawn_file_actions_destroy(&actions);
        ::close(fds[0]);
        if (failed != 0) {
            ::close(fds[1]);
            core::ThrowError("cannot start '{}': {}", program, std::strerror(failed));
        }
        pipe_ = ::fdopen(fds[1], "wb");
    }
    ~FfmpegWriter() {
        if (pipe_ != nullptr) {  // an error before the end: no partial video is left
            Finish(false);
            std::remove(path_.c_str());
        }
    }
    void Write(const uint8_t* rgb, size_t bytes) {
        if (std::fwrite(rgb, 1, bytes, pipe_) != bytes) {
            core::ThrowError("ffmpeg stopped reading frames (see its message above)");
        }
    }
    // Closes the pipe and waits; throws (when `check`) unless ffmpeg exited with 0.
    void Finish(bool check = true) {
        std::fclose(pipe_);
        pipe_ = nullptr;
        int status = 0;
        ::waitpid(pid_, &status, 0);
        if (check && !(WIFEXITED(status) && WEXITSTATUS(status) == 0)) {
            core::ThrowError("ffmpeg failed (exit status {}) writing the video",
                             WIFEXITED(status) ? WEXITSTATUS(status) : -1);
        }
    }

private:
    std::string path_;
    pid_t pid_ = 0;
    FILE* pipe_ = nullptr;
};

}  // namespace

void CheckCameraPathOutput(const CameraPathOptions& options) {
    t::io::CheckOutputPath("-o/--output", options.output);
    const std::string ext = t::io::LowerCaseExtension(options.output);
    if (ext != "png" && ext != "mp4") {
        core::ThrowError(
            "-o/--output '{}': with --camera-path use .png (a sequence of frames beside it, "
            "<name>_00000.png, ...) or .mp4 (H.264 through ffmpeg)",
            options.output);
    }
    if (ext == "mp4" && FindProgram("ffmpeg").empty()) {
        core::ThrowError(
            "-o/--output '{}': an .mp4 is encoded by the ffmpeg program, which is not on PATH "
            "(Debian: apt install ffmpeg); or write a .png sequence and encode it yourself",
            options.output);
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

    std::unique_ptr<FfmpegWriter> ffmpeg;
    const std::string video_temp = options.output + ".partial.mp4";
    if (video)
        ffmpeg =
            std::make_unique<FfmpegWriter>(FindProgram("ffmpeg"), video_temp, w, h, options.fps);
    std::vector<uint8_t> rgb(size_t(w) * h * 3);
    const auto start = std::chrono::steady_clock::now();
    double last_report = -1.0;
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
        const std::vector<rendering::RenderOutput> outputs =
            backend.RenderBatch(views, config, batch_options);
        for (size_t k = 0; k < outputs.size(); ++k) {
            if (video) {
                const uint8_t* rgba = outputs[k].color.Data<uint8_t>();
                for (size_t p = 0; p < size_t(w) * h; ++p)
                    std::memcpy(&rgb[3 * p], &rgba[4 * p], 3);
                ffmpeg->Write(rgb.data(), rgb.size());
            } else {
                const t::geometry::Image color = outputs[k].color.SelectChannels(0, 3);
                t::io::OutputFileSet files;
                files.Write(FramePath(options.output, begin + k),
                            [&](const std::string& p) { t::io::WriteImage(p, color); });
                files.Commit();
            }
        }
        const double seconds = core::MillisecondsSince(start) / 1000.0;
        if (end == frames.size() || seconds - last_report >= 1.0) {
            last_report = seconds;
            std::printf("frame %zu/%zu (%.0f%%), %.1f frames/s\n", end, frames.size(),
                        100.0 * double(end) / double(frames.size()),
                        double(end) / std::max(seconds, 1e-9));
            std::fflush(stdout);
        }
    }
    if (video) {
        ffmpeg->Finish();
        if (std::rename(video_temp.c_str(), options.output.c_str()) != 0) {
            core::ThrowError("cannot rename '{}' to '{}': {}", video_temp, options.output,
                             std::strerror(errno));
        }
        std::printf("wrote %s\n", options.output.c_str());
    } else {
        std::printf("wrote %s .. %s\n", FramePath(options.output, 0).c_str(),
                    FramePath(options.output, frames.size() - 1).c_str());
    }
    return frames.size();
}

}  // namespace gs_render
