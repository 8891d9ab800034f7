// gs-render: renders a Gaussian splat scene (3DGS PLY or .splat, or the built-in default
// scene) from a cameras.json view or a look-at/orbit camera to PNG, depth and float dumps.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "../InputPathValidators.h"
#include "../NumberValidators.h"
#include "../RunReportingErrors.h"
#include "CameraPathRender.h"
#include "FilamentRender.h"
#include "GsRenderOptions.h"
#include "RenderOutputs.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/camera/PinholeCamera.h"
#include "open3d/core/CrashReport.h"
#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/core/Timer.h"
#include "open3d/t/geometry/PointCloudStatistics.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/ImageIO.h"
#include "open3d/t/io/OutputFiles.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/t/io/SplatHierarchyIO.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/LodCut.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanBackendRegistry.h"

namespace {

using namespace open3d;
using gs_render::CheckImageMemory;
using gs_render::CheckOutputs;
using gs_render::Options;
using gs_render::PathOptions;
using gs_render::WriteOutputs;
namespace rendering = open3d::visualization::rendering;

Eigen::Vector3d ToVec(const std::vector<double>& v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

using apps::kFinite;
using apps::kPositive;
using apps::kUnit;

// --view of --cameras, read before the scene (a bad index fails at once, not after seconds of
// loading); nothing without --cameras.
std::optional<camera::PinholeCamera> ReadChosenView(const Options& opt) {
    if (opt.cameras.empty()) return std::nullopt;
    const auto views = camera::ReadCamerasJson(opt.cameras);
    if (opt.view < 0 || opt.view >= static_cast<int>(views.size())) {
        core::ThrowError("--view {}: '{}' has {} views (0..{})", opt.view, opt.cameras,
                         views.size(), static_cast<int>(views.size()) - 1);
    }
    return views[opt.view].camera;
}

camera::PinholeCamera ChooseCamera(const Options& opt,
                                   const std::optional<camera::PinholeCamera>& json_view,
                                   const t::geometry::PointCloud& cloud, bool default_scene) {
    const bool look_at_flags =
        !opt.eye.empty() || !opt.center.empty() || !opt.up.empty() || opt.fov.has_value();
    camera::PinholeCamera cam;
    camera::LookAtCamera look_at;
    if (json_view) {
        cam = *json_view;
        // Look-at edits pivot on the point of the view axis nearest the scene centre.
        const Eigen::Vector3d forward = cam.GetRotation().row(2).transpose();
        const double distance =
            std::max(0.1, (t::geometry::ComputeMedianCenter(cloud) - cam.GetCenter()).dot(forward));
        look_at = cam.ToLookAt(distance);
    } else if (default_scene) {
        look_at = rendering::GetDefaultSceneLookAt();
        cam = rendering::GetDefaultSceneCamera();
    } else {
        // No cameras: look at the scene centre from -z (3DGS captures are usually y-down).
        look_at.center = t::geometry::ComputeMedianCenter(cloud);
        look_at.eye = look_at.center + Eigen::Vector3d(0, 0,
                                                       -2.5 * t::geometry::ComputeDistanceQuantile(
                                                                  cloud, look_at.center, 0.8));
        look_at.up = Eigen::Vector3d(0, -1, 0);
        look_at.vertical_fov_deg = 50.0;
        cam = camera::PinholeCamera::FromLookAt(look_at, 800, 800);
    }
    if (look_at_flags || opt.orbit_angle != 0.0) {
        if (!opt.eye.empty()) look_at.eye = ToVec(opt.eye);
        if (!opt.center.empty()) look_at.center = ToVec(opt.center);
        if (!opt.up.empty()) look_at.up = ToVec(opt.up);
        if (opt.fov) look_at.vertical_fov_deg = *opt.fov;
        look_at = camera::OrbitLookAt(look_at, opt.orbit_angle);
        cam = camera::PinholeCamera::FromLookAt(look_at, cam.width, cam.height);
    }
    // One given size keeps the camera's aspect ratio.
    return cam.ResizedKeepingAspect(opt.width, opt.height);
}

// The hierarchy for --lod-budget: --lod, else <input>.lod beside the scene (what gs-convert
// --lod writes), else built from the scene now (and not kept).
t::geometry::SplatHierarchy LoadOrBuildHierarchy(const Options& opt,
                                                 const t::geometry::PointCloud& cloud) {
    const auto start = std::chrono::steady_clock::now();
    std::string path = opt.lod;
    if (path.empty() && !opt.input.empty() && std::filesystem::exists(opt.input + ".lod")) {
        path = opt.input + ".lod";
    }
    if (!path.empty()) {
        t::geometry::SplatHierarchy hierarchy = t::io::ReadSplatHierarchy(path);
        const std::string mismatch = t::geometry::HierarchySourceMismatch(hierarchy, cloud);
        if (!mismatch.empty()) {
            core::ThrowError(
                "{} '{}' was not built from --input '{}': {}. Rebuild it (gs-convert '{}' OUT "
                "--lod writes OUT.lod) or remove it",
                opt.lod.empty() ? "the hierarchy beside the scene" : "--lod", path, opt.input,
                mismatch, opt.input);
        }
        if (hierarchy.scene_fingerprint == 0) {
            core::LogWarning(
                "'{}': a hierarchy file of version 1 carries no fingerprint of its scene: only "
                "its leaf count and SH degree were checked against '{}'",
                path, opt.input);
        }
        std::printf("level of detail: hierarchy of %lld nodes read from %s in %.1f ms\n",
                    static_cast<long long>(hierarchy.NumNodes()), path.c_str(),
                    core::MillisecondsSince(start));
        return hierarchy;
    }
    std::printf(
        "level of detail: building the hierarchy of %lld splats (gs-convert --lod "
        "writes it beside the scene once)...\n",
        static_cast<long long>(cloud.NumPoints()));
    std::fflush(stdout);
    t::geometry::SplatHierarchy hierarchy = t::geometry::BuildSplatHierarchy(cloud);
    std::printf("level of detail: hierarchy of %lld nodes built in %.1f ms\n",
                static_cast<long long>(hierarchy.NumNodes()), core::MillisecondsSince(start));
    return hierarchy;
}

rendering::RenderConfig MakeConfig(const Options& opt) {
    rendering::RenderConfig config;
    config.sh_degree = opt.sh_degree;
    config.antialias = opt.antialias;
    config.near_plane = opt.near_plane;
    config.depth_order = opt.depth_order == "reference" ? rendering::DepthOrder::kReference
                                                        : rendering::DepthOrder::kCameraRelative;
    if (!opt.background.empty()) config.background = ToVec(opt.background);
    return config;
}

// The backend asked for; the default (Vulkan) falls back to the CPU reference, an explicit
// choice fails.
std::unique_ptr<rendering::GaussianSplatBackend> MakeBackend(const Options& opt) {
    try {
        return rendering::CreateGaussianSplatBackend(opt.backend);
    } catch (const core::Open3DError& e) {
        if (opt.backend_given || opt.backend != "vulkan") throw;
        std::fprintf(stderr,
                     "gs-render: no usable Vulkan device, rendering with the CPU reference "
                     "instead (slower; pass --backend cpu to silence this).\n  reason: %s\n",
                     e.what());
        return rendering::CreateGaussianSplatBackend("cpu");
    }
}

int Run(const Options& opt) {
    CheckOutputs(opt);
    const std::optional<camera::PinholeCamera> json_view = ReadChosenView(opt);
    if (!opt.lod.empty() && opt.lod_budget == 0) {
        core::ThrowError("--lod '{}' is read for --lod-budget: give a budget too", opt.lod);
    }
    if (opt.lod_budget > 0 && opt.UsesFilament()) {
        core::ThrowError("--lod-budget draws through the splat backend alone, not {}",
                         gs_render::kFilamentFlags);
    }
    rendering::vulkan::RegisterVulkanBackend();
    const auto start = std::chrono::steady_clock::now();
    t::geometry::PointCloud cloud;
    const bool default_scene = opt.input.empty();
    if (default_scene) {
        cloud = rendering::CreateDefaultGaussianSplatScene();
    } else {
        t::io::ReadPointCloud(opt.input, cloud);
        t::io::RequireGaussianSplat(opt.input, cloud);
    }
    const double load_ms = core::MillisecondsSince(start);
    std::printf("scene: %s, %lld splats, SH degree %d, loaded in %.1f ms\n",
                default_scene ? "built-in default" : opt.input.c_str(),
                static_cast<long long>(cloud.NumPoints()), cloud.GaussianSplatGetSHOrder(),
                load_ms);

    if (!opt.camera_path.empty()) {
        std::unique_ptr<rendering::GaussianSplatBackend> path_backend = MakeBackend(opt);
        path_backend->SetScene(cloud);
        gs_render::RenderCameraPath(PathOptions(opt), *path_backend, MakeConfig(opt));
        std::printf("total time %.1f ms\n", core::MillisecondsSince(start));
        return 0;
    }
    const camera::PinholeCamera cam = ChooseCamera(opt, json_view, cloud, default_scene);
    CheckImageMemory(opt, cam);
    rendering::RenderConfig config = MakeConfig(opt);
    std::unique_ptr<rendering::GaussianSplatBackend> backend = MakeBackend(opt);
    const std::string backend_name = backend->GetName();
    if (opt.UsesFilament()) {
        gs_render::FilamentRenderOptions fo;
        fo.backend = backend_name;
        fo.sphere = opt.sphere;
        fo.plane = opt.plane;
        fo.splats = !opt.meshes_only;
        fo.sphere_center = default_scene ? rendering::GetDefaultSceneMeshSphere().center
                                         : t::geometry::ComputeMedianCenter(cloud);
        fo.sphere_radius =
            opt.sphere_radius.value_or(default_scene ? rendering::GetDefaultSceneMeshSphere().radius
                                                     : 0.3 * t::geometry::ComputeDistanceQuantile(
                                                                 cloud, fo.sphere_center, 0.8));
        fo.background = config.background;
        fo.frames = opt.frames;
        fo.depth = !opt.depth_output.empty();
        backend.reset();  // the Filament scene makes its own
        const gs_render::FilamentImages images =
            gs_render::RenderWithFilament(cloud, cam, config, fo);
        WriteOutputs(opt, images.color, fo.depth ? &images.depth : nullptr,
                     "merged splat and mesh depth", nullptr, nullptr);
        std::printf("total time %.1f ms\n", core::MillisecondsSince(start));
        return 0;
    }
    int64_t lod_nodes = 0;
    if (opt.lod_budget > 0) {
        auto* vulkan = dynamic_cast<rendering::vulkan::GaussianSplatVulkanBackend*>(backend.get());
        // Every node goes to the device: refused with the sizes before the hierarchy is read
        // or built (minutes for 1e8 splats) when even its least size cannot fit.
        if (vulkan != nullptr) {
            vulkan->CheckHierarchyFits(cloud.NumPoints(), cloud.GetGaussianSplatArrays().sh_degree);
        }
        const t::geometry::SplatHierarchy hierarchy = LoadOrBuildHierarchy(opt, cloud);
        config.lod_budget = opt.lod_budget;
        if (vulkan != nullptr) {
            vulkan->SetSceneHierarchy(cloud, hierarchy);  // the cut is chosen on the GPU
        } else {
            // The CPU reference draws the cut the GPU would choose (its mirror), as a scene.
            const std::vector<int64_t> nodes =
                rendering::cpu::CutLikeGpu(hierarchy, cam, opt.lod_budget).nodes;
            lod_nodes = static_cast<int64_t>(nodes.size());
            backend->SetScene(t::geometry::ExtractSplatNodes(hierarchy, cloud, nodes));
        }
    } else {
        backend->SetScene(cloud);
    }
    const auto render_start = std::chrono::steady_clock::now();
    backend->RenderGeometryStage(cam, config);
    rendering::RenderOutput out;
    rendering::CompositeInputs inputs;  // the depth image to write, if any
    inputs.expected_depth = !opt.depth_output.empty() && opt.depth_kind != "median";
    inputs.median_depth = !opt.depth_output.empty() && opt.depth_kind == "median";
    inputs.splat_id = !opt.id_output.empty();
    backend->RenderCompositeStage(out, inputs);
    const double render_ms = core::MillisecondsSince(render_start);
    const auto& s = out.stats;
    // Threads matter to the CPU reference only; the GPU reports its own pass times.
    const std::string where = backend_name == "cpu"
                                  ? fmt::format("cpu, {} threads", core::GetNumThreads())
                                  : backend_name;
    std::printf(
        "render: %dx%d, backend %s: geometry %.1f ms, composite %.1f ms, "
        "total %.1f ms (%lld visible splats, %lld tile entries%s)\n",
        cam.width, cam.height, where.c_str(), s.geometry_ms, s.composite_ms, render_ms,
        static_cast<long long>(s.num_visible), static_cast<long long>(s.num_tile_entries),
        s.error_flags ? ", ENTRIES DROPPED: raise the capacity limits" : "");

    if (opt.lod_budget > 0) {
        if (s.lod_cut_nodes > 0) lod_nodes = s.lod_cut_nodes;
        std::printf("level of detail: cut of %lld nodes (budget %llu) of %lld splats\n",
                    static_cast<long long>(lod_nodes),
                    static_cast<unsigned long long>(opt.lod_budget),
                    static_cast<long long>(cloud.NumPoints()));
    }
    const auto& depth = opt.depth_kind == "median" ? out.depth_median : out.depth_expected;
    WriteOutputs(opt, out.color.SelectChannels(0, 3), opt.depth_output.empty() ? nullptr : &depth,
                 opt.depth_kind + " depth", opt.float_output.empty() ? nullptr : &out.color,
                 opt.id_output.empty() ? nullptr : &out.splat_id);
    std::printf("total time %.1f ms\n", core::MillisecondsSince(start));
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    open3d::core::InstallCrashReport();
    Options opt;
    CLI::App app{
        "gs-render: render a 3D Gaussian Splatting scene to PNG.\n"
        "Without --input it renders the built-in default scene from its default camera.\n"
        "Camera: a cameras.json view (--cameras, --view), or a look-at camera (--eye, --center,\n"
        "--up, --fov) optionally orbited about --up through --center (--orbit-angle); look-at\n"
        "flags given with --cameras edit that view. Without either, the scene is framed from -z.\n"
        "--sphere or --filament render through Filament (meshes and splats composited with the\n"
        "depth test): on the X server of DISPLAY, else headless on EGL\n"
        "(OPEN3D_FILAMENT_PLATFORM=glx|egl chooses).",
        "gs-render"};
    app.add_option("-i,--input", opt.input,
                   "Scene file in any format gs-convert reads (docs/formats.md)")
        ->check(open3d::apps::ReadableInput(true));
    app.add_option("--cameras", opt.cameras, "3DGS cameras.json with the views")
        ->check(open3d::apps::ReadableInput(false));
    app.add_option("--view", opt.view, "View index in cameras.json")->capture_default_str();
    app.add_option("--width", opt.width,
                   "Output width (default: the camera's; one of width/height keeps the aspect)")
        ->check(CLI::Range(1, 16384));
    app.add_option("--height", opt.height, "Output height (default: the camera's)")
        ->check(CLI::Range(1, 16384));
    auto* backend_option =
        app.add_option("--backend", opt.backend,
                       "Rendering backend (vulkan falls back to cpu with a message when no Vulkan "
                       "device exists, unless given explicitly)")
            ->check(CLI::IsMember({"cpu", "vulkan", "placeholder"}))
            ->capture_default_str();
    app.add_option("-o,--output", opt.output,
                   "Colour image: .png (RGB8) or .npy (float RGB); other extensions are refused. "
                   "Every output's folder must exist; outputs appear only when all are written")
        ->capture_default_str();
    app.add_option("--depth-output", opt.depth_output,
                   "Depth image: .png (16-bit, view z * --depth-scale) or .npy (float); not the "
                   "same file as --output");
    app.add_option("--depth-kind", opt.depth_kind,
                   "expected: alpha-weighted mean z; median: z where alpha reaches 50%")
        ->check(CLI::IsMember({"expected", "median"}))
        ->capture_default_str();
    app.add_option("--depth-scale", opt.depth_scale,
                   "16-bit depth PNG units per scene unit; depths beyond 65535 / scale saturate "
                   "to 65535 (a warning gives the count)")
        ->check(kPositive)
        ->capture_default_str();
    app.add_option("--float-output", opt.float_output, "Premultiplied RGBA float32 dump (.npy)");
    app.add_option("--id-output", opt.id_output,
                   "ID image (.npy, int32 H x W): the index in --input of the splat that "
                   "contributes most to each pixel, -1 where none (docs/editing.md); not with "
                   "--filament/--sphere/--plane or --lod-budget");
    app.add_option("--sh-degree", opt.sh_degree, "Highest SH degree evaluated")
        ->check(CLI::Range(0, 3))
        ->capture_default_str();
    app.add_flag("--antialias", opt.antialias, "Antialias (Mip-Splatting) opacity compensation");
    app.add_option("--background", opt.background,
                   "Background colour r,g,b in 0..1 (default 0,0,0)")
        ->delimiter(',')
        ->expected(3)
        ->check(kUnit);
    app.add_option("--near", opt.near_plane, "Near cull distance (view z)")
        ->check(kPositive)
        ->capture_default_str();
    app.add_option("--depth-order", opt.depth_order,
                   "Depth that orders splats: reference (the original 3DGS rasterizer's float32 "
                   "view z) or camera-relative (accurate for scenes far from the origin; "
                   "docs/accuracy.md)")
        ->check(CLI::IsMember({"reference", "camera-relative"}))
        ->capture_default_str();
    app.add_option("--eye", opt.eye, "Look-at camera position x,y,z")
        ->delimiter(',')
        ->expected(3)
        ->check(kFinite);
    app.add_option("--center", opt.center, "Look-at target x,y,z")
        ->delimiter(',')
        ->expected(3)
        ->check(kFinite);
    app.add_option("--up", opt.up, "Look-at up vector x,y,z")
        ->delimiter(',')
        ->expected(3)
        ->check(kFinite);
    app.add_option("--fov", opt.fov, "Look-at vertical field of view in degrees")
        ->check(CLI::Range(1.0, 179.0));
    app.add_option("--orbit-angle", opt.orbit_angle,
                   "Rotate the eye about --up through --center by this many degrees")
        ->check(kFinite);
    app.add_option("--lod-budget", opt.lod_budget,
                   "Draw the scene's level-of-detail cut of at most this many splats (docs/lod.md; "
                   "0: the whole scene)")
        ->capture_default_str();
    app.add_option("--lod", opt.lod,
                   "Hierarchy file for --lod-budget (default: <input>.lod as gs-convert --lod "
                   "writes it, else the hierarchy is built from the scene first)")
        ->check(open3d::apps::ReadableInput(false));
    app.add_flag("--filament", opt.filament,
                 "Render through Filament (the Open3DScene offscreen path) instead of the "
                 "backend alone");
    app.add_flag("--sphere", opt.sphere,
                 "Add a red sphere (implies --filament) at the scene centre (the median splat "
                 "position): splats behind it are hidden, splats in front stay");
    app.add_flag("--plane", opt.plane,
                 "Add a grey lit square through the lower half of the sphere's place (implies "
                 "--filament), level with the camera's horizon, 6 sphere radii wide");
    app.add_flag("--meshes-only", opt.meshes_only,
                 "With --sphere/--plane: Filament draws the meshes alone, the splats are not "
                 "added (Filament's own frame: what the integrated frame costs beyond the splats)");
    app.add_option("--sphere-radius", opt.sphere_radius,
                   "Sphere radius (default: 0.3 x the 80th-percentile splat distance from the "
                   "centre; the default scene has its own place for the sphere)")
        ->check(kPositive);
    app.add_option("--frames", opt.frames,
                   "With --filament/--sphere/--plane: render this many frames read back like the "
                   "output, each running the whole pipeline, then as many presented to a "
                   "headless swap chain without readback (the viewer's frame); print the mean "
                   "times of all but the first of each")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    app.add_option("--camera-path", opt.camera_path,
                   "Render a camera path instead of one view: a cameras.json whose entries are "
                   "the keyframes (at their 'time' fields in seconds, else "
                   "--seconds-per-keyframe apart), every frame into -o: .png gives "
                   "<name>_00000.png, ... beside it, .mp4 an H.264 video (libx264; "
                   "docs/camera-paths.md)")
        ->check(CLI::ExistingFile);
    app.add_option("--fps", opt.fps, "--camera-path: frames per second")
        ->check(kPositive)
        ->capture_default_str();
    app.add_option("--seconds-per-keyframe", opt.seconds_per_keyframe,
                   "--camera-path: keyframe spacing where the entries have no 'time'")
        ->check(kPositive)
        ->capture_default_str();
    app.add_option("--crf", opt.crf,
                   "--camera-path into .mp4: x264's constant rate factor, 1 (best, largest) to "
                   "51 (worst); 18 looks lossless to most eyes")
        ->capture_default_str();
    app.add_option("--preset", opt.preset,
                   "--camera-path into .mp4: x264's speed preset (ultrafast, superfast, "
                   "veryfast, faster, fast, medium, slow, slower, veryslow): slower ones make "
                   "smaller files of the same quality")
        ->capture_default_str();
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }
    opt.backend_given = backend_option->count() > 0;
    return open3d::apps::RunReportingErrors("gs-render", [&opt] { return Run(opt); });
}
