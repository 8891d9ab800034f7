// gs-render's outputs (-o, --depth-output, --float-output, --id-output): checked before the
// scene is read (a run that cannot write its result fails at once), and written together.
#pragma once

#include <string>

#include "CameraPathRender.h"
#include "GsRenderOptions.h"
#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/Image.h"

namespace gs_render {

/// The camera-path part of the options.
CameraPathOptions PathOptions(const Options& opt);
/// Every output's path, extension and combination with the other flags; throws
/// core::Open3DError naming the flag.
void CheckOutputs(const Options& opt);
/// Writes the images asked for (null: not asked) to temporaries, then renames them all.
void WriteOutputs(const Options& opt, const open3d::t::geometry::Image& color,
                  const open3d::t::geometry::Image* depth, const std::string& depth_what,
                  const open3d::t::geometry::Image* float_color,
                  const open3d::t::geometry::Image* splat_id);
/// Refuses a view whose images and output copies would not fit in host memory.
void CheckImageMemory(const Options& opt, const open3d::camera::PinholeCamera& cam);

}  // namespace gs_render
