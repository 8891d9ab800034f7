// gs-render's Filament path (--sphere, --filament): the splats and an optional red sphere
// through the whole integration (Open3DScene: Filament meshes, Vulkan geometry and composite stages
// with the depth test, the blend), with the time of each part of the frame. The images come
// back to gs-render, which writes every output the same way (temporaries, then renames).
#pragma once

#include <Eigen/Core>

#include <string>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/Image.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

namespace gs_render {

struct FilamentRenderOptions {
    std::string backend = "auto";  ///< "auto": vulkan, else the placeholder (no splats)
    bool sphere = false;
    Eigen::Vector3d sphere_center = Eigen::Vector3d::Zero();
    double sphere_radius = 1.0;
    /// A grey lit square through the sphere's lower half (half a radius below its centre,
    /// side 6 radii), level with the camera's horizon: a second, larger mesh that splats
    /// stand in front of and behind.
    bool plane = false;
    bool splats = true;  ///< false: the meshes alone (the scene holds no splats)
    Eigen::Vector3d background = Eigen::Vector3d::Zero();
    int frames = 1;      ///< frames rendered; times are averaged over all but the first
    bool depth = false;  ///< also render the merged splat and mesh depth
};

struct FilamentImages {
    open3d::t::geometry::Image color;  ///< UInt8 [H, W, 3]
    open3d::t::geometry::Image depth;  ///< Float32 [H, W, 1] view z, 0 where nothing is; empty
                                       ///< unless FilamentRenderOptions::depth
};

/// Renders the images; prints the frame time split into geometry stage, Filament, composite
/// stage and readback. Throws core::Open3DError (e.g. GLX asked for without an X server).
FilamentImages RenderWithFilament(const open3d::t::geometry::PointCloud& cloud,
                                  const open3d::camera::PinholeCamera& camera,
                                  const open3d::visualization::rendering::RenderConfig& config,
                                  const FilamentRenderOptions& options);

}  // namespace gs_render
