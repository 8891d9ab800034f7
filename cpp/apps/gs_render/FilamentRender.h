// gs-render's Filament path (--sphere, --filament): the splats and an optional red sphere
// through the whole integration (Open3DScene: Filament meshes, Vulkan geometry and composite stages
// with the depth test, the blend), with the time of each part of the frame.
#pragma once

#include <Eigen/Core>

#include <string>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

namespace gs_render {

struct FilamentRenderOptions {
    std::string backend = "auto";  ///< "auto": vulkan, else the placeholder (no splats)
    bool sphere = false;
    Eigen::Vector3d sphere_center = Eigen::Vector3d::Zero();
    double sphere_radius = 1.0;
    Eigen::Vector3d background = Eigen::Vector3d::Zero();
    int frames = 1;  ///< frames rendered; times are averaged over all but the first
    std::string output;
    std::string depth_output;  ///< .png (16-bit, z * depth_scale) or .npy (float)
    double depth_scale = 1000.0;
};

/// Renders and writes the images; prints the frame time split into geometry stage, Filament,
/// Composite stage and readback. Throws core::Open3DError (e.g. no X server: run under xvfb-run).
void RenderWithFilament(const open3d::t::geometry::PointCloud& cloud,
                        const open3d::camera::PinholeCamera& camera,
                        const open3d::visualization::rendering::RenderConfig& config,
                        const FilamentRenderOptions& options);

}  // namespace gs_render
