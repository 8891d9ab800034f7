// The Visualizer in a real (Xvfb) window: geometry by name, camera fitting, the window
// picture against the offscreen render, the panel, injected input, resize and minimise,
// screenshots.
#include "open3d/visualization/visualizer/Visualizer.h"

#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <thread>
#include <utility>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/t/io/ImageIO.h"
#include "open3d/t/io/SplatPageFile.h"
#include "open3d/visualization/rendering/filament/FilamentRenderer.h"
#include "visualization/rendering/gaussian_splat/cpu/SplatTestScene.h"
#include "visualization/visualizer/VisualizerTestFixture.h"
#include "visualization/visualizer/XKeySender.h"

namespace open3d {
namespace tests {
namespace {

using visualization::Visualizer;

Eigen::Vector3d Project(const camera::PinholeCamera& camera, const Eigen::Vector3d& p) {
    const Eigen::Vector3d c = camera.GetRotation() * p + camera.GetTranslation();
    return Eigen::Vector3d(camera.fx * c.x() / c.z() + camera.cx,
                           camera.fy * c.y() / c.z() + camera.cy, c.z());
}

// Runs the loop until it has drawn everything it owes (RunOptions::until_idle); the deadline
// is reached only by a hang, never by a slow or busy machine.
visualization::RunOptions UntilIdle(std::function<void()> before_frame = {}) {
    visualization::RunOptions run;
    run.until_idle = true;
    run.max_seconds = 300.0;
    run.before_frame = std::move(before_frame);
    return run;
}

void Drag(Visualizer& vis, int button, double x0, double y0, double x1, double y1) {
    vis.OnCursorPos(x0, y0);
    vis.OnMouseButton(button, true, 0);
    vis.OnCursorPos(0.5 * (x0 + x1), 0.5 * (y0 + y1));
    vis.OnCursorPos(x1, y1);
    vis.OnMouseButton(button, false, 0);
}

// The viewer draws through BeginFrame / Draw / EndFrame: the splat geometry stage is
// submitted before Filament draws, the composite follows Filament's draw, and the compose
// view is drawn on the window and presented last.
TEST_F(VisualizerTest, FramesFollowTheSeedsOrder) {
    Visualizer& vis = MakeVisualizer();
    AddWallAndSphere(vis);
    std::vector<rendering::FrameEvent> events;
    renderer_->SetFrameEventListener(
        [&](rendering::FrameEvent e, const rendering::FilamentView*) { events.push_back(e); });
    const bool drawn = vis.RenderFrame();
    renderer_->SetFrameEventListener({});
    ASSERT_TRUE(drawn);
    using rendering::FrameEvent;
    const std::vector<FrameEvent> want = {FrameEvent::kBeginFrame,   FrameEvent::kGeometryStage,
                                          FrameEvent::kFilamentDraw, FrameEvent::kComposite,
                                          FrameEvent::kOverlay,      FrameEvent::kEndFrame};
    EXPECT_EQ(events, want);
}

TEST_F(VisualizerTest, GeometryByName) {
    Visualizer& vis = MakeVisualizer();
    AddWallAndSphere(vis);
    EXPECT_EQ(vis.GetGeometryNames(), (std::vector<std::string>{"wall", "sphere"}));
    EXPECT_TRUE(vis.HasGeometry("wall"));
    EXPECT_TRUE(vis.IsGeometryVisible("sphere"));
    // A taken name throws and changes nothing.
    EXPECT_THROW(vis.AddGeometry("wall", t::geometry::TriangleMesh::CreateSphere(1.0, 8)),
                 core::Open3DError);
    EXPECT_EQ(vis.GetGeometryNames().size(), 2u);
    vis.ShowGeometry("sphere", false);
    EXPECT_FALSE(vis.IsGeometryVisible("sphere"));
    // Update keeps the visibility.
    vis.UpdateGeometry("sphere", t::geometry::TriangleMesh::CreateSphere(0.25, 10));
    EXPECT_FALSE(vis.IsGeometryVisible("sphere"));
    EXPECT_THROW(vis.ShowGeometry("nothing", true), core::Open3DError);
    EXPECT_FALSE(vis.RemoveGeometry("nothing"));
    EXPECT_TRUE(vis.RemoveGeometry("wall"));
    EXPECT_EQ(vis.GetGeometryNames(), (std::vector<std::string>{"sphere"}));
    // Keys 1-9 toggle by panel order.
    PressKey(vis, GLFW_KEY_1);
    EXPECT_TRUE(vis.IsGeometryVisible("sphere"));
    PressKey(vis, GLFW_KEY_5);  // no fifth object: nothing happens
    EXPECT_TRUE(vis.RenderFrame());
}

TEST_F(VisualizerTest, ResetCameraFitsTheVisibleBounds) {
    Visualizer& vis = MakeVisualizer(200, 300);  // tall: the horizontal fov limits
    AddWallAndSphere(vis);
    t::geometry::TriangleMesh far_box = t::geometry::TriangleMesh::CreateSphere(1.0, 8);
    far_box.Translate(Eigen::Vector3d(50, 0, 0));
    vis.AddGeometry("far", far_box);
    for (bool far_visible : {true, false}) {
        SCOPED_TRACE(far_visible ? "far object visible" : "far object hidden");
        vis.ShowGeometry("far", far_visible);
        vis.ResetCamera();
        Eigen::Vector3d lo, hi;
        ASSERT_TRUE(vis.GetScene().GetScene().GetBounds(lo, hi));
        EXPECT_EQ(hi.x() > 40.0, far_visible);
        const camera::PinholeCamera camera = vis.GetCamera();
        EXPECT_EQ(camera.width, 200);
        EXPECT_EQ(camera.height, 300);
        for (int i = 0; i < 8; ++i) {
            const Eigen::Vector3d corner(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                                         i & 4 ? hi.z() : lo.z());
            const Eigen::Vector3d p = Project(camera, corner);
            EXPECT_GT(p.z(), 0.0);
            EXPECT_GE(p.x(), -0.5);
            EXPECT_LE(p.x(), camera.width - 0.5);
            EXPECT_GE(p.y(), -0.5);
            EXPECT_LE(p.y(), camera.height - 0.5);
        }
    }
    // The red sphere is in the picture once the far object is hidden.
    EXPECT_GT(CountRed(vis.CaptureScreenImage()), 50);
}

TEST_F(VisualizerTest, WindowShowsWhatRenderToImageRenders) {
    Visualizer& vis = MakeVisualizer();
    AddWallAndSphere(vis);
    const t::geometry::Image screen = vis.CaptureScreenImage();
    const t::geometry::Image offscreen = vis.RenderToImage();
    ASSERT_EQ(screen.GetRows(), 160);
    ASSERT_EQ(screen.GetCols(), 240);
    ASSERT_EQ(offscreen.NumPixels(), screen.NumPixels());
    // The compose view blends 8-bit mesh colour with the fp16 overlay in the 8-bit swap
    // chain; the offscreen path blends the same inputs in float on the host: 1 LSB apart
    // at most (InteractivePathTest measures the same).
    const uint8_t* a = screen.Data<uint8_t>();
    const uint8_t* b = offscreen.Data<uint8_t>();
    int worst = 0;
    for (int64_t i = 0; i < screen.NumPixels() * 3; ++i) {
        worst = std::max(worst, std::abs(int(a[i]) - int(b[i])));
    }
    EXPECT_LE(worst, 1);
    EXPECT_GT(CountRed(screen), 100);
    // Depth of the centre pixel: the sphere's front (z = 1.5) seen from the eye on the axis.
    const t::geometry::Image depth = vis.RenderToDepthImage();
    const float* z = depth.Data<float>();
    const double expected = 1.5 - vis.GetViewControl().GetEye().z();
    EXPECT_NEAR(z[80 * 240 + 120], expected, 2e-2 * expected);
}

TEST_F(VisualizerTest, PanelIsDrawnOverTheScene) {
    Visualizer& vis = MakeVisualizer(480, 320, true);
    AddWallAndSphere(vis);
    vis.RenderFrame();  // the panel's first frame sizes its window
    const t::geometry::Image with_panel = vis.CaptureScreenImage();
    vis.ShowSettings(false);
    const t::geometry::Image without = vis.CaptureScreenImage();
    const std::string dir = TempDir();
    t::io::WritePNG(dir + "/with_panel.png", with_panel);
    t::io::WritePNG(dir + "/without_panel.png", without);
    std::printf("panel screenshots in %s\n", dir.c_str());
    // The panel's title bar and first lines sit in the top-left corner; the right edge of
    // the window is outside the panel and unchanged.
    EXPECT_GT(MeanAbsDiff(with_panel, without, 8, 8, 150, 60), 15.0);
    EXPECT_LT(MeanAbsDiff(with_panel, without, 450, 0, 480, 320), 0.5);
    PressKey(vis, GLFW_KEY_H);
    EXPECT_TRUE(vis.IsSettingsShown());
}

TEST_F(VisualizerTest, HidingAnObjectRemovesItsPixels) {
    Visualizer& vis = MakeVisualizer();
    AddWallAndSphere(vis);
    EXPECT_GT(CountRed(vis.CaptureScreenImage()), 100);
    PressKey(vis, GLFW_KEY_2);  // the second object: the sphere
    EXPECT_FALSE(vis.IsGeometryVisible("sphere"));
    EXPECT_EQ(CountRed(vis.CaptureScreenImage()), 0);
    PressKey(vis, GLFW_KEY_2);
    EXPECT_GT(CountRed(vis.CaptureScreenImage()), 100);
}

TEST_F(VisualizerTest, InjectedInputMovesTheCamera) {
    Visualizer& vis = MakeVisualizer(480, 320, true);
    AddWallAndSphere(vis);
    vis.RenderFrame();  // lays out the panel
    visualization::ViewControl& view = vis.GetViewControl();
    const Eigen::Vector3d center = view.GetCenter(), eye = view.GetEye();
    const double distance = view.GetDistance();

    // A drag that starts on the panel belongs to ImGui: the camera stays.
    Drag(vis, GLFW_MOUSE_BUTTON_LEFT, 30, 20, 200, 120);
    EXPECT_TRUE(view.GetEye().isApprox(eye));

    // Left drag outside the panel orbits about the centre.
    vis.ShowSettings(false);  // the pictures compare the scene alone
    const t::geometry::Image before = vis.CaptureScreenImage();
    Drag(vis, GLFW_MOUSE_BUTTON_LEFT, 400, 200, 440, 180);
    EXPECT_TRUE(view.GetCenter().isApprox(center));
    EXPECT_NEAR(view.GetDistance(), distance, 1e-9);
    EXPECT_GT((view.GetEye() - eye).norm(), 0.05 * distance);
    const t::geometry::Image orbited = vis.CaptureScreenImage();
    EXPECT_GT(MeanAbsDiff(before, orbited, 0, 0, 480, 320), 1.0);

    // Wheel up zooms in; right drag pans.
    vis.OnCursorPos(400, 200);
    vis.OnScroll(0.0, 2.0);
    EXPECT_NEAR(view.GetDistance(), distance * 0.81, 1e-9);
    Drag(vis, GLFW_MOUSE_BUTTON_RIGHT, 400, 200, 420, 200);
    EXPECT_FALSE(view.GetCenter().isApprox(center));
    PressKey(vis, GLFW_KEY_R);
    EXPECT_TRUE(view.GetCenter().isApprox(center));
    EXPECT_TRUE(view.GetEye().isApprox(eye));
}

TEST_F(VisualizerTest, ResizeAndMinimise) {
    Visualizer& vis = MakeVisualizer(240, 160, true);
    AddWallAndSphere(vis);
    ASSERT_TRUE(vis.RenderFrame());
    const int64_t builds = vis.GetScene().GetView().GetTargetBuilds();
    // Shrink and grow a few times: each size gets its own targets, the old ones are
    // released before the new frame (ASan builds catch a use after free here).
    for (auto [w, h] : {std::pair{320, 200}, std::pair{200, 120}, std::pair{300, 220}}) {
        vis.SetWindowSize(w, h);
        ASSERT_TRUE(WaitForSize(vis, w, h)) << "the window never became " << w << "x" << h;
        const t::geometry::Image image = vis.CaptureScreenImage();
        EXPECT_EQ(image.GetCols(), w);
        EXPECT_EQ(image.GetRows(), h);
        EXPECT_EQ(vis.GetCamera().width, w);
        vis.ShowSettings(false);  // the panel covers the sphere in such small windows
        EXPECT_GT(CountRed(vis.CaptureScreenImage()), 50);
        vis.ShowSettings(true);
    }
    EXPECT_EQ(vis.GetScene().GetView().GetTargetBuilds(), builds + 3);

    // Minimised: GLFW reports a 0 x 0 framebuffer. Nothing is drawn, nothing crashes.
    vis.OnFramebufferSize(0, 0);
    EXPECT_FALSE(vis.RenderFrame());
    EXPECT_THROW(vis.CaptureScreenImage(), core::Open3DError);
    visualization::RunOptions run;
    run.max_seconds = 0.2;
    vis.Run(run);
    EXPECT_EQ(vis.GetCamera().width, 300);  // the camera keeps its last size
    vis.OnFramebufferSize(300, 220);
    EXPECT_EQ(vis.CaptureScreenImage().GetCols(), 300);

    // The window manager's requests (without one, as under plain Xvfb, nothing changes).
    vis.Minimize();
    vis.PollEvents();
    vis.Restore();
    vis.Maximize();
    for (int i = 0; i < 20; ++i) vis.PollEvents();
    if (vis.GetWidth() > 0) {
        EXPECT_EQ(vis.CaptureScreenImage().GetCols(), vis.GetWidth());
    }
}

TEST_F(VisualizerTest, RunStopsAfterTheFrameLimit) {
    Visualizer& vis = MakeVisualizer();
    AddWallAndSphere(vis);
    int before_frame_calls = 0;
    visualization::RunOptions run;
    run.continuous = true;
    run.max_frames = 4;
    run.before_frame = [&] { ++before_frame_calls; };
    vis.Run(run);
    EXPECT_EQ(before_frame_calls, 4);
    EXPECT_EQ(vis.GetFrameStatistics().GetCount(), 3);  // times between 4 presented frames
    EXPECT_GT(vis.GetFrameStatistics().GetSmoothedFrameMs(), 0.0);
    EXPECT_GT(vis.GetLastFrame().splat_stats.num_visible, 0);
    // Without `continuous`, a visualizer draws the frames it was asked for and is then idle.
    run = UntilIdle([&] { ++before_frame_calls; });
    int polls = 0;
    run.poll = [&] { ++polls; };
    before_frame_calls = 0;
    vis.PostRedraw();
    vis.Run(run);
    ASSERT_TRUE(vis.IsIdle());
    EXPECT_EQ(before_frame_calls, 2);
    EXPECT_EQ(polls, 3);  // every iteration: two drawn, then the one that found it idle
    // Idle, it sleeps on events until the time limit and still polls (ten times a second).
    run = {};
    run.max_seconds = 0.3;
    run.before_frame = [&] { ++before_frame_calls; };
    run.poll = [&] { ++polls; };
    polls = 0;
    vis.Run(run);
    EXPECT_EQ(before_frame_calls, 2);
    EXPECT_GE(polls, 1);
    // Q asks the loop to end.
    PressKey(vis, GLFW_KEY_Q);
    EXPECT_FALSE(vis.PollEvents());
}

double ProcessCpuSeconds() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
           1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

// The viewer's default window with the panel fully open (at 720 rows the "Rendering" header
// opens, whose widgets once asked for a redraw every frame): after the frames it was asked
// for, five seconds without input draw nothing and cost next to no CPU.
TEST_F(VisualizerTest, IdleAtTheDefaultWindowSize) {
    Visualizer& vis = MakeVisualizer(1280, 720, true);
    AddWallAndSphere(vis);
    int frames = 0;
    vis.Run(UntilIdle([&] { ++frames; }));  // the frames asked for by AddGeometry and the fit
    ASSERT_TRUE(vis.IsIdle());
    EXPECT_GE(frames, 1);
    EXPECT_LE(frames, 3);
    frames = 0;
    const double cpu_start = ProcessCpuSeconds();
    visualization::RunOptions run;
    run.before_frame = [&] { ++frames; };
    run.max_seconds = 5.0;
    vis.Run(run);
    const double cpu = ProcessCpuSeconds() - cpu_start;
    EXPECT_EQ(frames, 0);
    // Measured 0.0x s here (glfwWaitEventsTimeout wakes ten times a second); one frame of
    // this scene at 1280 x 720 on lavapipe costs more than 0.3 s of CPU.
    EXPECT_LT(cpu, 0.25) << "an idle viewer used " << cpu << " s of CPU in 5 s";
    // Changing a setting through the API draws again.
    rendering::RenderConfig config = std::as_const(vis).GetSplatConfig();
    config.antialias = !config.antialias;
    vis.SetSplatConfig(config);
    EXPECT_FALSE(vis.IsIdle());
    vis.Run(UntilIdle([&] { ++frames; }));
    EXPECT_GE(frames, 1);
}

// While the camera moves on a slow device the window shows a frame drawn at a fraction of
// its size, scaled up texel by texel, and the full-size frame once the motion stops. A
// 1 us budget makes every frame "slow": 240 x 160 is drawn at 60 x 40.
TEST_F(VisualizerTest, ReducedResolutionWhileTheCameraMoves) {
    Visualizer& vis = MakeVisualizer(240, 160, false, 1e-3);
    AddWallAndSphere(vis);
    const t::geometry::Image still = vis.CaptureScreenImage();
    EXPECT_EQ(vis.GetLastFrameDivisor(), 1);
    vis.OnCursorPos(120, 80);  // a drag held still: the camera counts as moving
    vis.OnMouseButton(GLFW_MOUSE_BUTTON_LEFT, true, 0);
    ASSERT_TRUE(vis.IsCameraMoving());
    const t::geometry::Image moving = vis.CaptureScreenImage();
    ASSERT_EQ(vis.GetLastFrameDivisor(), 4);
    ASSERT_EQ(moving.GetCols(), 240);
    // Nearest texel of a 60 x 40 picture: every aligned 4 x 4 block has one colour.
    const uint8_t* p = moving.Data<uint8_t>();
    int64_t off_block = 0;
    for (int y = 0; y < 160; ++y) {
        for (int x = 0; x < 240; ++x) {
            for (int c = 0; c < 3; ++c) {
                off_block += p[(y * 240 + x) * 3 + c] != p[((y / 4 * 4) * 240 + x / 4 * 4) * 3 + c];
            }
        }
    }
    EXPECT_EQ(off_block, 0);
    // The same scene: the sphere's red and the wall's blue where they were, different along
    // their edges only (measured: 0.87 levels mean, 256 red pixels against 232).
    const double diff = MeanAbsDiff(still, moving, 0, 0, 240, 160);
    std::printf("reduced frame: mean difference %.2f levels, red %lld of %lld\n", diff,
                static_cast<long long>(CountRed(moving)), static_cast<long long>(CountRed(still)));
    EXPECT_GT(CountRed(moving), CountRed(still) / 2);
    EXPECT_LT(diff, 4.0);
    EXPECT_GT(diff, 0.1) << "no reduced frame was drawn";
    // Released, the next frame the loop draws is full size again, equal to the first.
    vis.OnMouseButton(GLFW_MOUSE_BUTTON_LEFT, false, 0);
    vis.Run(UntilIdle());
    EXPECT_EQ(vis.GetLastFrameDivisor(), 1);
    EXPECT_FALSE(vis.IsCameraMoving());
    EXPECT_EQ(MeanAbsDiff(still, vis.CaptureScreenImage(), 0, 0, 240, 160), 0.0);
}

// A million small splats: on lavapipe the geometry stage of one frame takes seconds. A Q
// that reaches the window while it runs (sent through the X server, as a user's key is) is
// seen by the frame's waits, which poll events: the frame stops before its composite,
// nothing more is drawn, and the loop ends.
TEST_F(VisualizerTest, QDuringALongFrameStopsIt) {
    Visualizer& vis = MakeVisualizer(640, 400);
    std::vector<TestSplat> splats(1000000);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (TestSplat& s : splats) {
        s.position = Eigen::Vector3d(3.0 * u(rng), 2.0 * u(rng), 5.0 + u(rng));
        s.scale = Eigen::Vector3d::Constant(0.01);
        s.opacity = 0.3;
        s.color = Eigen::Vector3d(0.5 + 0.5 * u(rng), 0.5, 0.5);
    }
    vis.AddGeometry("many", MakeCloud(splats));
    vis.ResetCamera();
    ASSERT_TRUE(vis.RenderFrame());  // uploads the scene
    vis.GetViewControl().Orbit(2.0, 0.0);
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_TRUE(vis.RenderFrame());
    const double frame_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("a full frame of 1e6 splats at 640 x 400: %.2f s\n", frame_s);
    if (frame_s < 0.4) GTEST_SKIP() << "frames of " << frame_s << " s: too fast to hold one open";

    vis.GetViewControl().Orbit(2.0, 0.0);  // the next frame runs the geometry stage again
    // The key goes out through the X server once the frame's geometry stage is submitted,
    // so it arrives while that stage runs on the device, however busy the machine is.
    int frames = 0;
    bool sent = false;
    const uint64_t window = vis.GetX11WindowId();
    renderer_->SetFrameEventListener([&](rendering::FrameEvent e, const rendering::FilamentView*) {
        if (e != rendering::FrameEvent::kGeometryStage || sent) return;
        sent = true;
        SendXKey(window, "q");
    });
    visualization::RunOptions run;
    run.continuous = true;
    run.max_frames = 5;
    run.before_frame = [&] { ++frames; };
    const auto start = std::chrono::steady_clock::now();
    vis.Run(run);
    renderer_->SetFrameEventListener({});
    const double run_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(sent);
    EXPECT_EQ(frames, 1) << "Q did not end the loop within the frame it arrived in";
    EXPECT_TRUE(vis.GetLastFrame().cancelled) << "the frame ran to the end";
    EXPECT_FALSE(vis.PollEvents());
    std::printf("Q sent at the geometry stage stopped the frame after %.2f s\n", run_s);
}

// After a large scene arrives, a frame without splats that shows the notice in the panel is
// presented first; the real frame follows in the same call, and later frames are plain.
TEST_F(VisualizerTest, LargeSceneNoticeFrameComesFirst) {
    visualization::VisualizerOptions options;
    options.width = 240;
    options.height = 160;
    options.show_settings = true;
    options.first_frame_notice_splats = 100;  // the wall has 144
    Visualizer& vis = MakeVisualizer(options);
    AddWallAndSphere(vis);
    std::vector<rendering::FrameEvent> events;
    renderer_->SetFrameEventListener(
        [&](rendering::FrameEvent e, const rendering::FilamentView*) { events.push_back(e); });
    ASSERT_TRUE(vis.RenderFrame());
    using rendering::FrameEvent;
    const std::vector<FrameEvent> notice = {FrameEvent::kBeginFrame, FrameEvent::kGeometryStage,
                                            FrameEvent::kFilamentDraw, FrameEvent::kOverlay,
                                            FrameEvent::kEndFrame};
    const std::vector<FrameEvent> frame = {FrameEvent::kBeginFrame,   FrameEvent::kGeometryStage,
                                           FrameEvent::kFilamentDraw, FrameEvent::kComposite,
                                           FrameEvent::kOverlay,      FrameEvent::kEndFrame};
    std::vector<FrameEvent> want = notice;
    want.insert(want.end(), frame.begin(), frame.end());
    EXPECT_EQ(events, want);
    EXPECT_TRUE(vis.GetLastFrame().splats_drawn);
    EXPECT_TRUE(vis.GetStatus().empty());
    events.clear();
    vis.GetViewControl().Orbit(5.0, 0.0);
    ASSERT_TRUE(vis.RenderFrame());
    renderer_->SetFrameEventListener({});
    EXPECT_EQ(events, frame);
}

// Files dropped on the window go to the open callback; its errors become the panel's status.
TEST_F(VisualizerTest, DroppedFilesGoToTheOpenCallback) {
    Visualizer& vis = MakeVisualizer(240, 160, true);
    vis.OnDrop({"/x/a.ply"});
    EXPECT_NE(vis.GetStatus().find("not enabled"), std::string::npos) << vis.GetStatus();
    std::vector<std::string> opened;
    vis.SetOpenCallback([&](const std::vector<std::string>& paths) {
        if (paths[0] == "/bad.ply") core::ThrowError("/bad.ply: no such file");
        opened = paths;
        vis.SetStatus("");
    });
    vis.OnDrop({"/x/a.ply", "/x/b.spz"});
    EXPECT_EQ(opened, (std::vector<std::string>{"/x/a.ply", "/x/b.spz"}));
    EXPECT_TRUE(vis.GetStatus().empty());
    vis.OnDrop({"/bad.ply"});
    EXPECT_EQ(vis.GetStatus(), "/bad.ply: no such file");
    EXPECT_TRUE(vis.RenderFrame());  // the panel draws the message
}

// A paged file streams into the window: the loop draws on its own as pages arrive (no input,
// not continuous), the panel shows the progress line, the picture ends as the same splats
// added as a cloud give it, and once the stream settled an idle loop draws nothing.
TEST_F(VisualizerTest, StreamedSplatsArriveWithoutInput) {
    Visualizer& vis = MakeVisualizer(240, 160, true);
    // Distinct depths 0.001 apart seen straight along +z: the depth order cannot depend on
    // the slots the pool holds the splats in, so the pictures must be equal.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<int> order(2000);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    std::vector<TestSplat> splats(order.size());
    for (size_t i = 0; i < splats.size(); ++i) {
        splats[i].position = Eigen::Vector3d(2.0 * u(rng), 1.5 * u(rng), 3.0 + 0.001 * order[i]);
        splats[i].scale = Eigen::Vector3d::Constant(0.05);
        splats[i].opacity = 0.8;
        splats[i].color = Eigen::Vector3d(0.5 + 0.4 * u(rng), 0.5 + 0.4 * u(rng), 0.5);
    }
    const t::geometry::PointCloud cloud = MakeCloud(splats);
    const std::string paged = TempDir() + "/random.gspages";
    t::io::WriteSplatPages(paged, cloud, t::geometry::BuildSplatHierarchy(cloud), 64);
    rendering::SplatStreamOptions options;
    options.gpu_budget = uint64_t(1) << 20;  // every page
    options.reads_per_step = 2;
    vis.StreamSplats(paged, options);
    camera::PinholeCamera camera;  // at the origin, looking along +z
    camera.width = 240;
    camera.height = 160;
    camera.fx = camera.fy = 150.0;
    camera.cx = 119.5;
    camera.cy = 79.5;
    vis.SetCamera(camera);
    int frames = 0;
    vis.Run(UntilIdle([&] { ++frames; }));
    ASSERT_TRUE(vis.IsIdle());
    const rendering::SplatStreamProgress progress = *vis.GetStreamProgress();
    ASSERT_TRUE(progress.settled);
    EXPECT_GE(frames, 2);
    EXPECT_NE(rendering::FormatStreamProgress(progress).find("complete"), std::string::npos);
    EXPECT_EQ(progress.nodes_drawn, 2000);  // every leaf is in view
    // Settled and drawn: the line no longer changes and no step waits, so the loop sleeps.
    frames = 0;
    visualization::RunOptions run;
    run.before_frame = [&] { ++frames; };
    run.max_seconds = 1.0;
    vis.Run(run);
    EXPECT_EQ(frames, 0);
    const t::geometry::Image streamed = vis.RenderToImage();
    EXPECT_THROW(vis.AddGeometry("cloud", cloud), core::Open3DError);
    // Hidden (the panel's checkbox), the stream draws nothing: the empty scene's picture.
    vis.ShowStream(false);
    EXPECT_FALSE(vis.IsStreamVisible());
    const t::geometry::Image hidden = vis.RenderToImage();
    EXPECT_GT(MeanAbsDiff(streamed, hidden, 0, 0, 240, 160), 1.0);
    vis.ShowStream(true);
    EXPECT_EQ(MeanAbsDiff(streamed, vis.RenderToImage(), 0, 0, 240, 160), 0.0);
    EXPECT_TRUE(vis.StopStreaming());
    EXPECT_FALSE(vis.GetStreamProgress().has_value());
    EXPECT_THROW(vis.ShowStream(true), core::Open3DError);
    EXPECT_EQ(MeanAbsDiff(hidden, vis.RenderToImage(), 0, 0, 240, 160), 0.0);
    vis.AddGeometry("cloud", cloud);
    const t::geometry::Image whole = vis.RenderToImage();
    EXPECT_EQ(MeanAbsDiff(streamed, whole, 0, 0, 240, 160), 0.0);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
