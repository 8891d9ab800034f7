// gs-render's outputs: checked before the scene is read, written all or none.
#include "RenderOutputs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"
#include "open3d/t/io/ImageIO.h"
#include "open3d/t/io/OutputFiles.h"

namespace gs_render {

using namespace open3d;

gs_render::CameraPathOptions PathOptions(const Options& opt) {
    gs_render::CameraPathOptions path;
    path.path_file = opt.camera_path;
    path.fps = opt.fps;
    path.seconds_per_keyframe = opt.seconds_per_keyframe;
    path.width = opt.width;
    path.height = opt.height;
    path.output = opt.output;
    path.crf = opt.crf;
    path.preset = opt.preset;
    return path;
}

// Every output is checked before the scene is read: a run that cannot write its result
// fails at once instead of after loading and rendering, and the extension decides the
// format (a .jpg depth output was written as PNG bytes).
void CheckOutputs(const Options& opt) {
    if (!opt.camera_path.empty()) {
        const char* single = !opt.depth_output.empty()   ? "--depth-output"
                             : !opt.float_output.empty() ? "--float-output"
                             : !opt.id_output.empty()    ? "--id-output"
                             : opt.UsesFilament()        ? kFilamentFlags
                             : opt.lod_budget > 0        ? "--lod-budget"
                             : !opt.cameras.empty()      ? "--cameras"
                             : !opt.eye.empty() || !opt.center.empty() || opt.fov
                                 ? "--eye/--center/--fov"
                                 : nullptr;
        if (single != nullptr) {
            core::ThrowError(
                "{} is for a single view; --camera-path '{}' renders the path's "
                "cameras into -o only",
                single, opt.camera_path);
        }
        gs_render::CheckCameraPathOutput(PathOptions(opt));
        t::io::CheckOutputIsNotAnInput(
            "-o/--output", opt.output,
            {{"--input", opt.input}, {"--camera-path", opt.camera_path}});
        return;
    }
    struct Output {
        const char* flag;
        const std::string& path;
        std::vector<std::string> extensions;
        const char* formats;
    };
    const std::vector<Output> outputs = {
        {"-o/--output", opt.output, {"png", "npy"}, ".png (8-bit RGB) or .npy (float RGB)"},
        {"--depth-output",
         opt.depth_output,
         {"png", "npy"},
         ".png (16-bit, view z * --depth-scale) or .npy (float view z)"},
        {"--float-output", opt.float_output, {"npy"}, ".npy (premultiplied RGBA float32)"},
        {"--id-output", opt.id_output, {"npy"}, ".npy (int32 splat index, -1 where none)"},
    };
    for (size_t i = 0; i < outputs.size(); ++i) {
        const Output& o = outputs[i];
        if (o.path.empty() && i > 0) continue;  // optional outputs not asked for
        t::io::CheckOutputPath(o.flag, o.path);
        t::io::CheckOutputIsNotAnInput(
            o.flag, o.path,
            {{"--input", opt.input}, {"--cameras", opt.cameras}, {"--lod", opt.lod}});
        const std::string ext = t::io::LowerCaseExtension(o.path);
        if (std::find(o.extensions.begin(), o.extensions.end(), ext) == o.extensions.end()) {
            core::ThrowError("{} '{}': unknown extension '{}'; use {}", o.flag, o.path,
                             ext.empty() ? "(none)" : "." + ext, o.formats);
        }
        for (size_t j = 0; j < i; ++j) {
            if (!outputs[j].path.empty() && t::io::SameOutputPath(o.path, outputs[j].path)) {
                core::ThrowError("{} and {} are the same file '{}'; give each its own path",
                                 outputs[j].flag, o.flag, o.path);
            }
        }
    }
    if (!opt.float_output.empty() && opt.UsesFilament()) {
        core::ThrowError(
            "--float-output is not available with {} (the Filament path returns 8-bit colour)",
            kFilamentFlags);
    }
    if (!opt.id_output.empty() && (opt.UsesFilament() || opt.lod_budget > 0)) {
        core::ThrowError(
            "--id-output is not available with {}: its pixels show {}, not splats of --input",
            opt.lod_budget > 0 ? "--lod-budget" : kFilamentFlags,
            opt.lod_budget > 0 ? "merged level-of-detail nodes" : "meshes too");
    }
}

// Writes every requested image to a temporary beside its output, then renames them all:
// a failing write leaves neither a partial file nor some of the outputs without the rest.
void WriteOutputs(const Options& opt, const t::geometry::Image& color,
                  const t::geometry::Image* depth, const std::string& depth_what,
                  const t::geometry::Image* float_color, const t::geometry::Image* splat_id) {
    t::io::OutputFileSet files;
    files.Write(opt.output, [&](const std::string& path) { t::io::WriteImage(path, color); });
    int64_t saturated = 0;
    const bool depth_npy = t::io::LowerCaseExtension(opt.depth_output) == "npy";
    if (depth != nullptr) {
        files.Write(opt.depth_output, [&](const std::string& path) {
            if (depth_npy) {
                t::io::WriteNpy(path, *depth);
            } else {
                saturated = t::io::WritePNG16(path, *depth, opt.depth_scale);
            }
        });
    }
    if (float_color != nullptr) {
        files.Write(opt.float_output,
                    [&](const std::string& path) { t::io::WriteNpy(path, *float_color); });
    }
    if (splat_id != nullptr) {
        files.Write(opt.id_output,
                    [&](const std::string& path) { t::io::WriteNpy(path, *splat_id); });
    }
    files.Commit();
    std::printf("wrote %s\n", opt.output.c_str());
    if (depth != nullptr) {
        std::printf("wrote %s (%s)\n", opt.depth_output.c_str(), depth_what.c_str());
        if (saturated > 0) {
            std::fprintf(stderr,
                         "gs-render: warning: %lld of %lld depth pixels are farther than %g "
                         "scene units (65535 / --depth-scale %g) and were saturated to 65535 in "
                         "'%s'; lower --depth-scale or write .npy for exact depths\n",
                         static_cast<long long>(saturated),
                         static_cast<long long>(depth->NumPixels()), 65535.0 / opt.depth_scale,
                         opt.depth_scale, opt.depth_output.c_str());
        }
    }
    if (float_color != nullptr) std::printf("wrote %s (float RGBA)\n", opt.float_output.c_str());
    if (splat_id != nullptr) {
        std::printf("wrote %s (dominant splat per pixel, int32, -1 where none)\n",
                    opt.id_output.c_str());
    }
}

// The render's images and every copy the outputs make, before anything is drawn: the
// backends check their own images (colour RGBA32F and two float depths, 24 B/px), but the
// 8-bit colour, the depth image and the float dump are more (a 30000x30000 view passed the
// backend's check and was killed for memory writing them).
void CheckImageMemory(const Options& opt, const camera::PinholeCamera& cam) {
    uint64_t per_pixel = 4 * 4 + 4 + 4;  // the backend's images
    per_pixel += 3;                      // 8-bit RGB for the PNG (or 12 B: float RGB .npy)
    if (t::io::LowerCaseExtension(opt.output) == "npy") per_pixel += 9;
    if (!opt.depth_output.empty()) per_pixel += 4;  // 16-bit PNG or float .npy
    if (!opt.float_output.empty()) per_pixel += 16;
    if (!opt.id_output.empty()) per_pixel += 4;
    const uint64_t pixels = uint64_t(cam.width) * uint64_t(cam.height);
    const uint64_t available = core::AvailableHostMemory();
    const double scale = pixels * per_pixel > available
                             ? std::sqrt(double(available) / double(pixels * per_pixel)) * 0.9
                             : 1.0;
    core::RequireHostMemory(
        pixels * per_pixel,
        fmt::format("gs-render: a {}x{} render and its outputs ({} bytes a pixel)", cam.width,
                    cam.height, per_pixel),
        fmt::format("{}x{} would fit", std::max(1, int(cam.width * scale)),
                    std::max(1, int(cam.height * scale))));
}

}  // namespace gs_render
