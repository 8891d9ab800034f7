// The seed's frame order through FilamentRenderer's three calls: BeginFrame submits the
// geometry stage of every added view before Filament draws anything; each Draw then has
// Filament draw the view and the composite follow; EndFrame draws the compose views and
// presents. Checked from the renderer's own frame events.
#include <gtest/gtest.h>

#include <filament/Engine.h>
#include <filament/SwapChain.h>

#include <utility>
#include <vector>

#include "open3d/core/Exception.h"
#include "visualization/rendering/filament/FilamentTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using rendering::FrameEvent;
using Event = std::pair<FrameEvent, const rendering::FilamentView*>;

rendering::Open3DScene& AddSplatsAndSphere(rendering::Open3DScene& scene,
                                           const camera::PinholeCamera& camera) {
    scene.AddGeometry("wall", MakeSplatWall(4.0, 3.0, 12, Eigen::Vector3d(0.1, 0.2, 0.9)));
    AddRedSphere(scene.GetScene());
    scene.SetupCamera(camera);
    return scene;
}

TEST_F(FilamentTest, BeginFrameSubmitsEveryGeometryStageBeforeFilamentDraws) {
    const camera::PinholeCamera camera = MakeFilamentTestCamera(48, 32);
    rendering::Open3DScene& a = AddSplatsAndSphere(MakeOpen3DScene(), camera);
    rendering::Open3DScene& b = AddSplatsAndSphere(MakeOpen3DScene(), camera);
    std::vector<Event> events;
    renderer_->SetFrameEventListener(
        [&](FrameEvent e, const rendering::FilamentView* v) { events.emplace_back(e, v); });
    filament::Engine& engine = engine_->GetEngine();
    filament::SwapChain* swap_chain = engine.createSwapChain(
        uint32_t(camera.width), uint32_t(camera.height), filament::SwapChain::CONFIG_READABLE);
    rendering::FrameRequest request;
    request.read_color = true;
    renderer_->BeginFrame(swap_chain);
    const rendering::FrameResult frame_a = renderer_->Draw(a.GetView(), request);
    request.read_screen = true;
    const rendering::FrameResult frame_b = renderer_->Draw(b.GetView(), request);
    const t::geometry::Image screen = renderer_->EndFrame();
    renderer_->SetFrameEventListener({});
    engine.destroy(swap_chain);
    engine.flushAndWait();

    const rendering::FilamentView* va = &a.GetView();
    const rendering::FilamentView* vb = &b.GetView();
    const std::vector<Event> want = {
        {FrameEvent::kBeginFrame, nullptr}, {FrameEvent::kGeometryStage, va},
        {FrameEvent::kGeometryStage, vb},   {FrameEvent::kFilamentDraw, va},
        {FrameEvent::kComposite, va},       {FrameEvent::kFilamentDraw, vb},
        {FrameEvent::kComposite, vb},       {FrameEvent::kOverlay, va},
        {FrameEvent::kOverlay, vb},         {FrameEvent::kEndFrame, nullptr}};
    EXPECT_EQ(events, want);
    // Two views of equal scenes and cameras give the same picture, and the screen is it.
    ASSERT_EQ(frame_a.color.NumPixels(), int64_t(48 * 32));
    EXPECT_TRUE(frame_a.color.AsTensor() == frame_b.color.AsTensor());
    EXPECT_EQ(screen.NumPixels(), frame_b.color.NumPixels());
    EXPECT_TRUE(frame_a.splats_drawn && frame_a.scene_depth_used);
}

TEST_F(FilamentTest, FrameCallsOutOfOrderThrowAndLeaveTheRendererUsable) {
    const camera::PinholeCamera camera = MakeFilamentTestCamera(32, 24);
    rendering::Open3DScene& scene = AddSplatsAndSphere(MakeOpen3DScene(), camera);
    rendering::FrameRequest request;
    EXPECT_THROW(renderer_->Draw(scene.GetView(), request), core::Open3DError);
    EXPECT_THROW(renderer_->EndFrame(), core::Open3DError);
    renderer_->BeginFrame();
    EXPECT_THROW(renderer_->BeginFrame(), core::Open3DError);
    renderer_->Draw(scene.GetView(), request);
    renderer_->EndFrame();
    EXPECT_FALSE(renderer_->IsFrameBegun());
    // The one-call form still works after the three-call frame.
    EXPECT_EQ(scene.RenderToImage().NumPixels(), int64_t(32 * 24));
}

// Two views of one scene: the backend holds one view's sorted entries at a time, so the
// second view's composite re-runs its geometry stage and both pictures stay right.
TEST_F(FilamentTest, TwoViewsOfOneSceneCompositeTheirOwnGeometryStage) {
    const camera::PinholeCamera near_camera = MakeFilamentTestCamera(48, 32);
    camera::PinholeCamera moved = near_camera;
    moved.world_to_camera(0, 3) = 0.4;  // the scene shifts left in the image
    rendering::FilamentScene& scene = MakeScene();
    scene.AddGeometry("wall", MakeSplatWall(4.0, 3.0, 12, Eigen::Vector3d(0.1, 0.2, 0.9)));
    scene.AddGeometry("blob", MakeSplatBlob(0.0, 0.0, 1.5, 0.1, Eigen::Vector3d(0.9, 0.9, 0.2)));
    rendering::FilamentView& first = MakeView(near_camera);
    rendering::FilamentView& second = MakeView(moved);
    rendering::FrameRequest request;
    request.read_color = true;
    // Reference pictures, one view per frame.
    const rendering::FrameResult want_first = renderer_->Draw(scene, first, request);
    const rendering::FrameResult want_second = renderer_->Draw(scene, second, request);
    ASSERT_FALSE(want_first.color.AsTensor() == want_second.color.AsTensor());
    renderer_->AddView(scene, first);
    renderer_->AddView(scene, second);
    renderer_->BeginFrame();
    const rendering::FrameResult got_first = renderer_->Draw(first, request);
    const rendering::FrameResult got_second = renderer_->Draw(second, request);
    renderer_->EndFrame();
    renderer_->RemoveView(first);
    renderer_->RemoveView(second);
    EXPECT_TRUE(got_first.color.AsTensor() == want_first.color.AsTensor());
    EXPECT_TRUE(got_second.color.AsTensor() == want_second.color.AsTensor());
    EXPECT_GE(scene.GetCounters().geometry_stage_reruns, 1);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
