// gs-render's command line, as main() parses it (GsRender.cpp) and the output checks read it
// (RenderOutputs.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "open3d/camera/CameraPath.h"

namespace gs_render {

struct Options {
    std::string input;
    std::string cameras;
    int view = 0;
    int width = 0;
    int height = 0;
    std::string backend = "vulkan";
    bool backend_given = false;
    std::string output = "render.png";
    std::string depth_output;
    std::string depth_kind = "expected";
    double depth_scale = 1000.0;
    std::string float_output;
    std::string id_output;  // --id-output: the dominant splat of every pixel (.npy)
    int sh_degree = 3;
    bool antialias = false;
    std::vector<double> background;
    double near_plane = 0.2;
    std::string depth_order = "reference";
    std::vector<double> eye, center, up;
    std::optional<double> fov;
    double orbit_angle = 0.0;
    bool filament = false;
    bool sphere = false;
    bool plane = false;
    bool meshes_only = false;
    std::optional<double> sphere_radius;
    int frames = 1;
    uint64_t lod_budget = 0;  // 0: no level of detail
    std::string lod;          // hierarchy file; default <input>.lod, else built here
    std::string camera_path;  // --camera-path: render a path instead of one view
    double fps = 30.0;
    double seconds_per_keyframe = open3d::camera::kDefaultSecondsPerKeyframe;
    float crf = 23.0f;                // --camera-path -o x.mp4: x264's constant rate factor
    std::string preset = "veryfast";  // and its speed preset

    /// Any of kFilamentFlags: the frame goes through Filament.
    bool UsesFilament() const { return filament || sphere || plane || meshes_only; }
};

/// The flags that take the Filament path, as error messages name them.
inline constexpr const char* kFilamentFlags = "--filament/--sphere/--plane/--meshes-only";

}  // namespace gs_render
