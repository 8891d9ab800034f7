// gs-render --camera-path: a camera path (camera/CameraPath.h) rendered frame by frame through
// the backend's batched path into a PNG sequence or an H.264 MP4 (t/io/H264VideoWriter.h;
// docs/camera-paths.md).
#pragma once

#include <cstddef>
#include <string>

#include "open3d/camera/CameraPath.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"

namespace gs_render {

struct CameraPathOptions {
    std::string path_file;  ///< cameras.json entries, "time" optional
    double fps = 30.0;
    double seconds_per_keyframe = open3d::camera::kDefaultSecondsPerKeyframe;  ///< where no "time"
    int width = 0;  ///< 0: the keyframes' size (one of the two: aspect kept)
    int height = 0;
    /// .png: frames at <stem>_00000.png, <stem>_00001.png, ... beside it; .mp4: one video.
    std::string output;
    int batch = 8;                    ///< views a RenderBatch call renders
    float crf = 23.0f;                ///< .mp4: x264's constant rate factor, 1 (best) .. 51
    std::string preset = "veryfast";  ///< .mp4: x264's speed preset
};

/// Refuses an output before any work: an extension other than .png and .mp4, a missing folder,
/// for .mp4 an unknown x264 preset or a rate factor outside [1, 51].
void CheckCameraPathOutput(const CameraPathOptions& options);

/// Reads the path, renders every frame (RenderBatch of `options.batch` views at a time) and
/// writes them, printing progress; returns the number of frames. Every frame of a PNG
/// sequence goes through a temporary, so an interrupted run leaves no half-written frame.
size_t RenderCameraPath(const CameraPathOptions& options,
                        open3d::visualization::rendering::GaussianSplatBackend& backend,
                        const open3d::visualization::rendering::RenderConfig& config);

}  // namespace gs_render
