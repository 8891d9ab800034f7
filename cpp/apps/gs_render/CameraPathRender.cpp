#include "CameraPathRender.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "open3d/camera/CameraPath.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
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
                writer->WriteFrame(outputs[k].color.Data<uint8_t>(), 4);
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
