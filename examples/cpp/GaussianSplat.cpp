// GaussianSplat: the interactive viewer (docs/viewer.md). Opens a splat scene in any format
// t::io reads (docs/formats.md) or the built-in default scene, adds a red sphere mesh that
// shows the depth compositing of meshes and splats, and runs the Visualizer: orbit/pan/zoom,
// the ImGui settings panel, screenshots. Test and benchmark flags: --frames,
// --exit-after-seconds, --screenshot-dir, --screenshot-on-exit, --spin.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "apps/NumberValidators.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/Timer.h"
#include "open3d/t/geometry/PointCloudStatistics.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/t/io/SplatHierarchyIO.h"
#include "open3d/t/io/SplatPageFile.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/visualizer/BackgroundCloudReader.h"
#include "open3d/visualization/visualizer/Visualizer.h"

namespace {

using namespace open3d;
namespace rendering = open3d::visualization::rendering;
namespace vis = open3d::visualization;

struct Options {
    std::string input;
    int width = 1280, height = 720;
    std::string backend = "auto";
    std::string sharing = "auto";
    std::string cameras;
    int view = 0;
    std::vector<double> up;
    bool no_sphere = false;
    double sphere_radius = 0.0;
    bool hide_panel = false;
    int sh_degree = 3;
    bool antialias = false;
    std::string screenshot_dir = ".";
    int64_t frames = 0;
    double exit_after_seconds = 0.0;
    bool screenshot_on_exit = false;
    double spin_degrees = 0.0;
    bool continuous = false;
    double interactive_frame_ms = 100.0;
    std::string gpu_budget = "auto";
    bool compact_pool = false;
    double lod_target_ms = 0.0;
};

bool IsPagedFile(const std::string& path) {
    return std::filesystem::path(path).extension() == ".gspages";
}

// The red sphere mesh at `center` (--sphere-radius overrides `radius`) unless --no-sphere.
void AddSphere(vis::Visualizer& viewer, const Eigen::Vector3d& center, double radius,
               const Options& opt) {
    if (opt.no_sphere) return;
    if (opt.sphere_radius > 0.0) radius = opt.sphere_radius;
    t::geometry::TriangleMesh sphere = t::geometry::TriangleMesh::CreateSphere(radius, 40);
    sphere.Translate(center);
    rendering::MaterialRecord red;
    red.shader = rendering::kShaderDefaultLit;
    red.base_color = Eigen::Vector4f(1.0f, 0.0f, 0.0f, 1.0f);
    viewer.AddGeometry("sphere", sphere, red);
}

// Empties the viewer: the stream, then every named geometry.
void ClearScene(vis::Visualizer& viewer) {
    viewer.StopStreaming();
    for (const std::string& old : std::vector<std::string>(viewer.GetGeometryNames())) {
        viewer.RemoveGeometry(old);
    }
}

// Streams a paged file (gs-convert --pages) into a GPU pool of --gpu-budget bytes as the
// scene, with the sphere at the centre of its bounds (0.05 x their diagonal).
void StreamScene(vis::Visualizer& viewer, const std::string& path, const Options& opt) {
    rendering::SplatStreamOptions stream;
    stream.gpu_budget = rendering::ParseGpuBudget(opt.gpu_budget);
    stream.compact_storage = opt.compact_pool;
    // What can be refused is checked before the shown scene goes: the file's header and
    // page table, the budget against its pages, the backend.
    if (viewer.GetBackendName() != "vulkan") {
        core::ThrowError("streaming {} needs the vulkan backend, not {}", path,
                         viewer.GetBackendName());
    }
    rendering::StreamPoolPages(
        t::io::SplatPageFile(path), stream.gpu_budget,
        viewer.GetScene().GetScene().GetSplatRenderer().GetBackend().MaxSceneSplats(),
        stream.compact_storage);
    ClearScene(viewer);
    viewer.StreamSplats(path, stream);
    Eigen::Vector3d lo, hi;
    viewer.GetScene().GetScene().GetSplatRenderer().GetBounds(lo, hi);
    AddSphere(viewer, 0.5 * (lo + hi), 0.05 * (hi - lo).norm(), opt);
    const auto progress = viewer.GetStreamProgress();
    std::printf("GaussianSplat: streaming %s: %lld pages into a pool of %lld (--gpu-budget %s%s)\n",
                path.c_str(), static_cast<long long>(progress->file_pages),
                static_cast<long long>(progress->pool_pages), opt.gpu_budget.c_str(),
                opt.compact_pool ? ", half precision" : "");
    std::fflush(stdout);
}

// The level-of-detail hierarchy of `cloud`, read from `path`.lod (gs-convert --lod writes it
// beside the scene) when that was built from it, else built here (--lod-target-ms).
std::shared_ptr<const t::geometry::SplatHierarchy> SceneHierarchy(
    const std::string& path, const t::geometry::PointCloud& cloud) {
    const auto start = std::chrono::steady_clock::now();
    const std::string lod = path + ".lod";
    if (!path.empty() && std::filesystem::exists(lod)) {
        auto hierarchy =
            std::make_shared<const t::geometry::SplatHierarchy>(t::io::ReadSplatHierarchy(lod));
        const std::string mismatch = t::geometry::HierarchySourceMismatch(*hierarchy, cloud);
        if (mismatch.empty()) {
            std::printf("GaussianSplat: level of detail: %s read in %.1f ms\n", lod.c_str(),
                        core::MillisecondsSince(start));
            return hierarchy;
        }
        core::LogWarning("'{}' was not built from '{}' ({}); building the hierarchy", lod, path,
                         mismatch);
    }
    std::printf("GaussianSplat: level of detail: building the hierarchy of %lld splats...\n",
                static_cast<long long>(cloud.NumPoints()));
    std::fflush(stdout);
    auto hierarchy = std::make_shared<const t::geometry::SplatHierarchy>(
        t::geometry::BuildSplatHierarchy(cloud));
    std::printf("GaussianSplat: level of detail: %lld nodes built in %.1f ms\n",
                static_cast<long long>(hierarchy->NumNodes()), core::MillisecondsSince(start));
    std::fflush(stdout);
    return hierarchy;
}

// Puts `cloud` (read from `path`; empty for the built-in scene) into the viewer as the scene
// (replacing the one shown, if any) with the red sphere at its centre unless --no-sphere, and
// with --lod-target-ms its level-of-detail hierarchy.
void ShowScene(vis::Visualizer& viewer, const t::geometry::PointCloud& cloud,
               const std::string& name, const std::string& path, bool default_scene,
               const Options& opt) {
    ClearScene(viewer);
    viewer.AddGeometry(name, cloud);
    if (opt.lod_target_ms > 0.0) viewer.SetSplatHierarchy(name, SceneHierarchy(path, cloud));
    Eigen::Vector3d center;
    double radius = 0.0;
    if (default_scene) {
        center = rendering::GetDefaultSceneMeshSphere().center;
        radius = rendering::GetDefaultSceneMeshSphere().radius;
    } else {
        center = t::geometry::ComputeMedianCenter(cloud);
        radius = 0.3 * t::geometry::ComputeDistanceQuantile(cloud, center, 0.8);
    }
    AddSphere(viewer, center, radius, opt);
}

int Run(const Options& opt) {
    // Fail before reading a large scene when no window can be opened.
    const std::string no_display = rendering::FilamentUnavailableReason();
    if (!no_display.empty()) core::ThrowError("cannot open a window: {}", no_display);
    const bool default_scene = opt.input.empty();
    // A bad --view fails before a long load.
    std::optional<camera::PinholeCamera> start_camera;
    if (!opt.cameras.empty()) {
        const std::vector<camera::CameraView> views = camera::ReadCamerasJson(opt.cameras);
        if (opt.view < 0 || opt.view >= static_cast<int>(views.size())) {
            core::ThrowError("--view {}: {} has {} views (0..{})", opt.view, opt.cameras,
                             views.size(), static_cast<int>(views.size()) - 1);
        }
        start_camera = views[opt.view].camera;
    }
    const std::string name =
        default_scene ? "default_scene" : std::filesystem::path(opt.input).stem().string();

    vis::VisualizerOptions vo;
    vo.title = "GaussianSplat - " + name;
    vo.width = opt.width;
    vo.height = opt.height;
    vo.scene.backend = opt.backend;
    vo.scene.sharing = rendering::ParseSplatSharing(opt.sharing);
    vo.up = opt.up.size() == 3 ? Eigen::Vector3d(opt.up[0], opt.up[1], opt.up[2])
            : default_scene    ? Eigen::Vector3d(0, 1, 0)
                               : Eigen::Vector3d(0, -1, 0);
    vo.home_pitch_deg = 20.0;  // look down on the scene a little: ground planes show
    vo.show_settings = !opt.hide_panel;
    vo.screenshot_dir = opt.screenshot_dir;
    vo.interactive_frame_ms = opt.interactive_frame_ms;
    vo.lod_target_ms = opt.lod_target_ms;
    vis::Visualizer viewer(vo);
    viewer.GetSplatConfig().sh_degree = opt.sh_degree;
    viewer.GetSplatConfig().antialias = opt.antialias;
    viewer.SetBackground(Eigen::Vector4f(0.1f, 0.1f, 0.12f, 1.0f));

    // The scene is read on a worker thread while the window shows the progress (file size,
    // seconds so far) in the panel; closing the window meanwhile ends the program.
    const auto start = std::chrono::steady_clock::now();
    t::geometry::PointCloud cloud;
    vis::BackgroundCloudReader reader;
    double shown_s = -1.0;
    // The panel's progress line, twice a second; true when it changed.
    const auto show_progress = [&] {
        const double now = core::MillisecondsSince(start) / 1000.0;
        if (now - shown_s < 0.5) return false;
        viewer.SetStatus(reader.Describe());
        shown_s = now;
        return true;
    };
    const bool streamed = !default_scene && IsPagedFile(opt.input);
    if (default_scene) {
        cloud = rendering::CreateDefaultGaussianSplatScene();
    } else if (streamed) {
        StreamScene(viewer, opt.input, opt);
    } else {
        reader.Start(opt.input);
        std::printf("GaussianSplat: loading %s\n", opt.input.c_str());
        std::fflush(stdout);
        std::optional<t::geometry::PointCloud> loaded;
        while (!(loaded = reader.TakeResult())) {  // rethrows the reader's error
            if (!viewer.PollEvents()) return 0;
            if (show_progress()) viewer.RenderFrame();
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        cloud = std::move(*loaded);
        viewer.SetStatus("");
    }
    if (!streamed) {
        std::printf("GaussianSplat: scene %s, %lld splats, SH degree %d, loaded in %.1f ms\n",
                    default_scene ? "built-in default" : opt.input.c_str(),
                    static_cast<long long>(cloud.NumPoints()), cloud.GaussianSplatGetSHOrder(),
                    core::MillisecondsSince(start));
        ShowScene(viewer, cloud, name, opt.input, default_scene, opt);
    }
    if (start_camera) {
        viewer.SetCamera(*start_camera);
    } else if (default_scene) {
        viewer.SetCamera(rendering::GetDefaultSceneLookAt());
    } else {
        viewer.ResetCamera();
    }
    std::printf(
        "GaussianSplat: window 0x%llx, %dx%d, backend %s; press H for the panel, Q to quit\n",
        static_cast<unsigned long long>(viewer.GetX11WindowId()), viewer.GetWidth(),
        viewer.GetHeight(), viewer.GetBackendName().c_str());
    std::fflush(stdout);

    // Another file (dropped on the window or typed into the panel) is read on a worker
    // thread: the viewer keeps drawing the current scene and shows the read's progress.
    viewer.SetOpenCallback([&](const std::vector<std::string>& paths) {
        if (IsPagedFile(paths.front())) {
            // Errors show in the panel; a refused file leaves the scene as it was.
            if (reader.IsBusy()) {
                core::ThrowError("{} is still loading; open {} after it", reader.GetPath(),
                                 paths.front());
            }
            StreamScene(viewer, paths.front(), opt);
            viewer.ResetCamera();
            return;
        }
        reader.Start(paths.front());
        viewer.SetStatus(reader.Describe());
    });
    vis::RunOptions run;
    run.poll = [&] {
        if (!reader.IsBusy()) return;
        try {
            if (std::optional<t::geometry::PointCloud> loaded = reader.TakeResult()) {
                const std::string stem = std::filesystem::path(reader.GetPath()).stem().string();
                ShowScene(viewer, *loaded, stem, reader.GetPath(), false, opt);
                viewer.ResetCamera();
                viewer.SetStatus("");
                std::printf("GaussianSplat: opened %s, %lld splats\n", reader.GetPath().c_str(),
                            static_cast<long long>(loaded->NumPoints()));
                std::fflush(stdout);
                return;
            }
        } catch (const std::exception& e) {
            viewer.SetStatus(e.what(), true);
            std::fprintf(stderr, "GaussianSplat: %s\n", e.what());
            return;
        }
        show_progress();  // SetStatus asks for the frame that shows it
    };
    run.continuous = opt.continuous || opt.frames > 0 || opt.spin_degrees != 0.0;
    run.max_frames = opt.frames;
    run.max_seconds = opt.exit_after_seconds;
    if (opt.spin_degrees != 0.0) {
        run.before_frame = [&viewer, &opt] {
            viewer.GetViewControl().Orbit(opt.spin_degrees, 0.0);
            viewer.NoteCameraMotion();
        };
    }
    viewer.Run(run);
    // --screenshot-on-exit promises a file: a run that saved none fails (it exited 0).
    int status = 0;
    if (opt.screenshot_on_exit) {
        const std::string path = viewer.RequestScreenshot();
        // A frame the panel's input holds back or a cancelled one leaves the shot pending.
        for (int tries = 0; tries < 4 && viewer.HasPendingScreenshot(); ++tries) {
            if (!viewer.RenderFrame()) break;  // minimised: nothing to draw
        }
        if (viewer.GetLastScreenshotPath() != path) {
            std::fprintf(stderr, "GaussianSplat: error: --screenshot-on-exit saved nothing: %s\n",
                         !viewer.GetLastScreenshotError().empty()
                             ? viewer.GetLastScreenshotError().c_str()
                             : "the window drew no frame (minimised?)");
            status = 1;
        }
    }
    if (const auto progress = viewer.GetStreamProgress()) {
        std::printf("GaussianSplat: %s\n", rendering::FormatStreamProgress(*progress).c_str());
    }
    std::printf("GaussianSplat: %dx%d, %s\n", viewer.GetWidth(), viewer.GetHeight(),
                vis::FormatSummary(viewer.GetFrameStatistics().Summarize()).c_str());
    const rendering::RenderStats& s = viewer.GetLastFrame().splat_stats;
    // A hierarchy scene's splats are its nodes, of which the level-of-detail cut draws some.
    const std::string cut =
        s.lod_cut_nodes > 0 ? fmt::format(" in a level-of-detail cut of {} nodes", s.lod_cut_nodes)
                            : "";
    std::printf(
        "GaussianSplat: last frame: %lld of %lld splats visible%s, %lld tile entries, GPU project "
        "%.2f ms, sort %.2f ms, composite %.2f ms%s\n",
        static_cast<long long>(s.num_visible), static_cast<long long>(s.num_splats), cut.c_str(),
        static_cast<long long>(s.num_tile_entries), s.gpu_project_ms, s.gpu_sort_ms,
        s.gpu_composite_ms,
        s.geometry_reused ? " (geometry stage reused: the camera did not move)" : "");
    return status;
}

}  // namespace

int main(int argc, char** argv) {
    Options opt;
    CLI::App app{
        "GaussianSplat: interactive viewer for 3D Gaussian Splatting scenes, drawn with\n"
        "Vulkan compute (splats) and Filament (meshes, the panel). Opens SCENE (.ply,\n"
        ".compressed.ply, .splat, .spz, .sog or a SOG folder, .gltf, .glb, .ksplat) or,\n"
        "without one, the built-in default scene, and adds a red sphere mesh to\n"
        "show depth compositing. The file is read while the window shows the progress; drop\n"
        "another file on the window (or type its path into the panel) to open it instead.\n"
        "A paged file (.gspages, from gs-convert --pages) is streamed instead: a coarse\n"
        "picture at once, finer pages read into a GPU pool of --gpu-budget bytes while the\n"
        "viewer stays interactive, the progress in the panel and at exit.\n"
        "Needs an X server (run under `xvfb-run -a` without a display).\n"
        "\n"
        "Mouse: left drag orbits, right/middle/shift+left drag pans, wheel zooms.\n"
        "Keys: arrows orbit (shift: pan), +/- zoom, R resets the camera (fits the visible\n"
        "geometry), 1-9 toggle the objects in panel order (1 = the scene, 2 = the sphere),\n"
        "H hides/shows the panel, P saves a screenshot into --screenshot-dir, Q/Esc quit.\n"
        "A frame is drawn after input or a change only (an idle viewer sleeps), unless\n"
        "--continuous, --frames or --spin is given. At exit it prints the frame time summary\n"
        "(back-to-back frames only, without the first 3) and the last frame's GPU times.",
        "GaussianSplat"};
    app.add_option("scene", opt.input, "Splat scene file or SOG folder (default: built-in scene)")
        ->check(CLI::ExistingPath);
    app.add_option("--width", opt.width, "Window width in pixels")
        ->check(CLI::Range(1, 16384))
        ->capture_default_str();
    app.add_option("--height", opt.height, "Window height in pixels")
        ->check(CLI::Range(1, 16384))
        ->capture_default_str();
    app.add_option("--backend", opt.backend,
                   "Splat backend: auto (vulkan where a device exists, else placeholder, which "
                   "draws no splats and says so), vulkan, cpu, placeholder")
        ->check(CLI::IsMember({"auto", "vulkan", "cpu", "placeholder"}))
        ->capture_default_str();
    app.add_option("--sharing", opt.sharing,
                   "How splat images reach Filament: auto, zero-copy, host-copy")
        ->check(CLI::IsMember({"auto", "zero-copy", "host-copy"}))
        ->capture_default_str();
    app.add_option("--cameras", opt.cameras, "Start from a view of this 3DGS cameras.json")
        ->check(CLI::ExistingFile);
    app.add_option("--view", opt.view, "View index in --cameras")->capture_default_str();
    app.add_option("--up", opt.up,
                   "World up x,y,z of the orbit camera (default 0,-1,0 for files, the 3DGS "
                   "convention; 0,1,0 for the built-in scene)")
        ->delimiter(',')
        ->expected(3)
        ->check(apps::kFinite);
    app.add_flag("--no-sphere", opt.no_sphere, "Do not add the red sphere");
    app.add_option("--sphere-radius", opt.sphere_radius,
                   "Sphere radius. The sphere is centred on the median splat position, with "
                   "radius 0.3 x the 80th-percentile splat distance from there by default (the "
                   "built-in scene has its own place and size for it)")
        ->check(apps::kPositive);
    app.add_flag("--hide-panel", opt.hide_panel, "Start with the settings panel hidden");
    app.add_option("--sh-degree", opt.sh_degree, "Initial SH degree cap")
        ->check(CLI::Range(0, 3))
        ->capture_default_str();
    app.add_flag("--antialias", opt.antialias, "Start with antialiasing on");
    app.add_option("--screenshot-dir", opt.screenshot_dir,
                   "Folder for screenshot_NNNN.png (P key, panel button, --screenshot-on-exit); "
                   "made when missing")
        ->capture_default_str();
    app.add_flag("--continuous", opt.continuous,
                 "Draw frames back to back even when nothing changes (timing)");
    app.add_option("--frames", opt.frames,
                   "Draw continuously and exit after this many frames (0: no limit)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app.add_option("--exit-after-seconds", opt.exit_after_seconds,
                   "Exit after this many seconds (0: no limit)")
        ->check(apps::kNonNegative)
        ->capture_default_str();
    app.add_flag("--screenshot-on-exit", opt.screenshot_on_exit,
                 "Draw one more frame at exit and save it as a screenshot");
    app.add_option("--interactive-frame-ms", opt.interactive_frame_ms,
                   "While the camera moves (drag, keys, wheel, --spin), frames whose full-size "
                   "time exceeded this are drawn at 1/2 or 1/4 of each side and scaled up; "
                   "the full-size frame follows when the motion stops (0: always full size)")
        ->check(apps::kNonNegative)
        ->capture_default_str();
    app.add_option("--lod-target-ms", opt.lod_target_ms,
                   "While the camera moves, draw the scene through a level-of-detail cut whose "
                   "budget holds this many ms of GPU time per frame (the hierarchy is read from "
                   "SCENE.lod, which gs-convert --lod writes, or built at start); still, every "
                   "splat. Vulkan only; 0: off (docs/viewer.md \"Level of detail\")")
        ->check(apps::kNonNegative)
        ->capture_default_str();
    app.add_option("--gpu-budget", opt.gpu_budget,
                   "GPU memory for a streamed .gspages scene's pool (K, M, G, T: powers of "
                   "1024); the pool holds whole pages, at least one. auto: 1G, or as many "
                   "pages as the device holds in one scene where that is less")
        ->capture_default_str();
    app.add_flag("--compact-pool", opt.compact_pool,
                 "Store a streamed .gspages scene's pool at half precision: about 1.8 times "
                 "the splats in --gpu-budget, 83-88 dB against the CPU reference instead of "
                 "100");
    app.add_option("--spin", opt.spin_degrees,
                   "Orbit the camera by this many degrees every frame, drawing continuously "
                   "(timing: the splat geometry stage then runs every frame)")
        ->check(apps::kFinite)
        ->capture_default_str();
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }
    try {
        return Run(opt);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "GaussianSplat: error: %s\n", e.what());
        return 1;
    }
}
