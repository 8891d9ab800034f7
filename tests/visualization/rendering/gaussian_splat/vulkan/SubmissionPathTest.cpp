// The Vulkan backend's submission path (Render, RenderBatch, SubmitBatch / WaitBatch): both
// stages in one submission per frame slot, recordings submitted again with new cameras,
// batches of many views and frames in flight. Every image is compared bit for bit with the
// stage path or a fresh backend (same shaders, same order of operations: any difference is a
// bug, not rounding); the stage path itself is checked against the CPU reference in
// VulkanBackendTest.cpp. The fixture's validation check (synchronization validation on)
// covers the barriers and lifetimes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <functional>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/CommandTally.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"
#include "visualization/rendering/gaussian_splat/vulkan/VulkanTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;
using SubmissionPath = VulkanTest;

// `n` views of the default scene at w x h, the camera slid sideways a little per view.
std::vector<camera::PinholeCamera> SlidingViews(int n, int w, int h) {
    std::vector<camera::PinholeCamera> views;
    for (int i = 0; i < n; ++i) {
        camera::PinholeCamera cam = GetDefaultSceneCamera(w, h);
        cam.world_to_camera(0, 3) += 0.08 * i;
        cam.world_to_camera(1, 3) -= 0.03 * i;
        views.push_back(cam);
    }
    return views;
}

void ExpectSameImages(const RenderOutput& a, const RenderOutput& b) {
    EXPECT_TRUE(a.color.AsTensor() == b.color.AsTensor());
    EXPECT_TRUE(a.depth_expected.AsTensor() == b.depth_expected.AsTensor());
    EXPECT_TRUE(a.depth_median.AsTensor() == b.depth_median.AsTensor());
    EXPECT_EQ(a.stats.num_visible, b.stats.num_visible);
    EXPECT_EQ(a.stats.num_tile_entries, b.stats.num_tile_entries);
    EXPECT_EQ(a.stats.error_flags, b.stats.error_flags);
}

TEST_F(SubmissionPath, OneSubmissionEqualsTheStagePath) {
    auto backend = MakeBackend();
    backend->SetFramesInFlight(2);  // the default on GPUs (lavapipe's is 1)
    backend->SetScene(CreateDefaultGaussianSplatScene());
    RenderConfig config;
    config.background = Eigen::Vector3d(0.1, 0.2, 0.3);
    const auto views = SlidingViews(3, 72, 40);
    std::vector<RenderOutput> submitted;
    for (const camera::PinholeCamera& cam : views) {
        submitted.push_back(backend->Render(cam, config));
        ASSERT_FALSE(submitted.back().color.IsEmpty());
        ASSERT_FALSE(submitted.back().depth_expected.IsEmpty());
        ASSERT_FALSE(submitted.back().depth_median.IsEmpty());
        EXPECT_GT(submitted.back().stats.num_tile_entries, 1000);
    }
    // One recording per frame slot served the three cameras.
    EXPECT_EQ(backend->GetCounters().recordings, 2);
    EXPECT_EQ(backend->GetCounters().submissions, 3);
    EXPECT_TRUE(backend->GetLastBatchStats().recording_reused);
    // The stage path records its geometry stage once too and submits it again per camera.
    for (size_t i = 0; i < views.size(); ++i) {
        SCOPED_TRACE("view " + std::to_string(i));
        ExpectSameImages(submitted[i], RenderStages(*backend, views[i], config));
    }
    EXPECT_EQ(backend->GetCounters().recordings, 3);
    EXPECT_EQ(backend->GetCounters().geometry_runs, 3);
}

TEST_F(SubmissionPath, AResubmittedRecordingWithANewCameraEqualsAFreshRecording) {
    const auto views = SlidingViews(2, 64, 48);
    auto reused = MakeBackend();
    reused->SetFramesInFlight(1);  // one slot: the second frame re-submits the first recording
    reused->SetScene(CreateDefaultGaussianSplatScene());
    reused->Render(views[0], {});
    const RenderOutput second = reused->Render(views[1], {});
    EXPECT_TRUE(reused->GetLastBatchStats().recording_reused);
    EXPECT_EQ(second.stats.host_record_ms, 0.0);
    auto fresh = MakeBackend();
    fresh->SetScene(CreateDefaultGaussianSplatScene());
    const RenderOutput recorded = fresh->Render(views[1], {});
    EXPECT_FALSE(fresh->GetLastBatchStats().recording_reused);
    ExpectSameImages(second, recorded);
    // What the recording bakes in forces a new one: the background (a composite constant),
    // the size, the outputs.
    RenderConfig grey;
    grey.background = Eigen::Vector3d(0.5, 0.5, 0.5);
    const RenderOutput on_grey = reused->Render(views[1], grey);
    EXPECT_FALSE(reused->GetLastBatchStats().recording_reused);
    EXPECT_FALSE(on_grey.color.AsTensor() == second.color.AsTensor());
    ExpectSameImages(on_grey, RenderStages(*reused, views[1], grey));
    CompositeInputs colour_only;
    colour_only.expected_depth = colour_only.median_depth = false;
    const RenderOutput colour = reused->Render(views[1], {}, colour_only);
    EXPECT_TRUE(colour.depth_expected.IsEmpty());
    EXPECT_TRUE(colour.color.AsTensor() == second.color.AsTensor());
}

TEST_F(SubmissionPath, ABatchEqualsSingleRendersAndSplitsWhenItDoesNotFit) {
    auto backend = MakeBackend();
    backend->SetScene(CreateDefaultGaussianSplatScene());
    const auto views = SlidingViews(7, 48, 32);
    std::vector<RenderOutput> singles;
    for (const auto& cam : views) singles.push_back(backend->Render(cam, {}));
    BatchOptions options;
    options.expected_depth = options.median_depth = true;
    const std::vector<RenderOutput> batch = backend->RenderBatch(views, {}, options);
    ASSERT_EQ(batch.size(), views.size());
    EXPECT_EQ(backend->GetLastBatchStats().submissions, 1);
    for (size_t i = 0; i < views.size(); ++i) {
        SCOPED_TRACE("view " + std::to_string(i));
        ExpectSameImages(batch[i], singles[i]);
    }
    // Room for three views per submission: 3 + 3 + 1, still exact.
    const uint64_t view_bytes = 48 * 32 * (16 + 4 + 4);
    backend->SetBatchBudget(3 * view_bytes);
    EXPECT_EQ(backend->MaxViewsPerSubmission(48, 32, options), 3u);
    const std::vector<RenderOutput> split = backend->RenderBatch(views, {}, options);
    EXPECT_EQ(backend->GetLastBatchStats().submissions, 3);
    ASSERT_EQ(split.size(), views.size());
    for (size_t i = 0; i < views.size(); ++i) {
        SCOPED_TRACE("split view " + std::to_string(i));
        ExpectSameImages(split[i], singles[i]);
    }
    EXPECT_THROW(backend->SubmitBatch({views.begin(), views.begin() + 4}, {}, options),
                 core::Open3DError);
    // Cameras of two sizes are refused.
    EXPECT_THROW(backend->RenderBatch({views[0], views[1].Resized(40, 32)}, {}, options),
                 core::Open3DError);
    // Without readback the outputs carry the counts only.
    options.read_back = false;
    const std::vector<RenderOutput> counts = backend->RenderBatch(views, {}, options);
    EXPECT_TRUE(counts[2].color.IsEmpty());
    EXPECT_EQ(counts[2].stats.num_tile_entries, singles[2].stats.num_tile_entries);
}

TEST_F(SubmissionPath, EightBitColourIsTheFloatResultRounded) {
    // The device converts float to unorm when it stores (Vulkan allows any rounding within
    // 0.6 ULP of the exact value): every channel lies within 1 of round(255 x) of the float
    // image, and a batch equals single 8-bit renders bit for bit.
    auto backend = MakeBackend();
    backend->SetScene(CreateDefaultGaussianSplatScene());
    const auto views = SlidingViews(3, 64, 48);
    BatchOptions eight_bit;
    eight_bit.color_uint8 = true;
    const std::vector<RenderOutput> batch = backend->RenderBatch(views, {}, eight_bit);
    for (size_t i = 0; i < views.size(); ++i) {
        SCOPED_TRACE("view " + std::to_string(i));
        ASSERT_EQ(batch[i].color.GetDtype(), core::Dtype::UInt8);
        const t::geometry::Image rounded = ColorToUInt8(backend->Render(views[i], {}).color);
        const uint8_t* a = batch[i].color.Data<uint8_t>();
        const uint8_t* b = rounded.Data<uint8_t>();
        int max_diff = 0;
        int64_t nonzero = 0;
        for (int64_t k = 0; k < rounded.NumPixels() * 4; ++k) {
            max_diff = std::max(max_diff, std::abs(int(a[k]) - int(b[k])));
            nonzero += a[k] != 0;
        }
        EXPECT_LE(max_diff, 1);
        EXPECT_GT(nonzero, 1000);  // not a blank image
        const std::vector<RenderOutput> one = backend->RenderBatch({views[i]}, {}, eight_bit);
        EXPECT_TRUE(one[0].color.AsTensor() == batch[i].color.AsTensor());
    }
}

// Runs `check` for the Vulkan backend and the CPU reference, each with RGBA32F and RGBA8
// colour (its options and the bytes of a 48 x 32 view), under a trace naming the case.
void ForBothBackendsAndFormats(
    GaussianSplatBackend& vulkan, GaussianSplatBackend& reference,
    const std::function<void(GaussianSplatBackend&, BatchOptions, size_t view_bytes)>& check) {
    for (GaussianSplatBackend* backend : {&vulkan, &reference}) {
        for (const bool uint8 : {false, true}) {
            SCOPED_TRACE(backend->GetName() + (uint8 ? " uint8" : " float32"));
            BatchOptions options;
            options.color_uint8 = uint8;
            check(*backend, options, 48 * 32 * 4 * (uint8 ? 1 : 4));
        }
    }
}

// Colours rendered into the caller's memory (BatchOptions::color_destination, Python's
// render_batch) equal the images of an ordinary batch, across submissions (3 + 3 + 1 views)
// and for both colour formats; on the CPU backend too. Outputs then carry no colour image.
TEST_F(SubmissionPath, ColoursIntoTheCallersMemoryEqualTheImages) {
    auto vulkan = MakeBackend();
    cpu::CpuBackend reference;
    const t::geometry::PointCloud scene = CreateDefaultGaussianSplatScene();
    vulkan->SetScene(scene);
    reference.SetScene(scene);
    const auto views = SlidingViews(7, 48, 32);
    vulkan->SetBatchBudget(3 * 48 * 32 * 16);
    ForBothBackendsAndFormats(
        *vulkan, reference,
        [&](GaussianSplatBackend& backend, BatchOptions options, size_t view_bytes) {
            const std::vector<RenderOutput> images = backend.RenderBatch(views, {}, options);
            std::vector<uint8_t> memory(views.size() * view_bytes, 0xAB);
            options.color_destination = memory.data();
            const std::vector<RenderOutput> into = backend.RenderBatch(views, {}, options);
            for (size_t i = 0; i < views.size(); ++i) {
                SCOPED_TRACE("view " + std::to_string(i));
                EXPECT_TRUE(into[i].color.IsEmpty());
                EXPECT_EQ(std::memcmp(memory.data() + i * view_bytes,
                                      images[i].color.AsTensor().RawData(), view_bytes),
                          0);
                EXPECT_EQ(into[i].stats.num_tile_entries, images[i].stats.num_tile_entries);
            }
        });
}

// BatchHostMemory: the Vulkan backend imports it and the device writes the colours straight
// into it (RGBA32F from the composite, RGBA8 by a copy; no host copy); each submission of a
// split batch lands at its own offset. The bytes equal an ordinary batch's images; memory outside
// the views is left alone; too little memory is refused; the import is dropped once the
// caller lets the memory go. The CPU backend copies into it as into any memory.
TEST_F(SubmissionPath, ColoursIntoBatchHostMemoryEqualTheImages) {
    auto vulkan = MakeBackend();
    vulkan->SetFramesInFlight(2);  // two submissions at different offsets in flight at once
    cpu::CpuBackend reference;
    const t::geometry::PointCloud scene = CreateDefaultGaussianSplatScene();
    vulkan->SetScene(scene);
    reference.SetScene(scene);
    const auto views = SlidingViews(6, 48, 32);
    // 2 + 2 + 2 views: the first slot takes the first and the last submission, at two offsets.
    vulkan->SetBatchBudget(2 * 48 * 32 * 16);
    const bool imports = vulkan->GetContext().CanImportHostMemory();
    if (std::getenv("CI") != nullptr) {
        EXPECT_TRUE(imports) << "lavapipe has VK_EXT_external_memory_host: it must be used";
    }
    ForBothBackendsAndFormats(
        *vulkan, reference,
        [&](GaussianSplatBackend& backend, BatchOptions options, size_t view_bytes) {
            const std::vector<RenderOutput> images = backend.RenderBatch(views, {}, options);
            BatchHostMemory memory((views.size() + 1) * view_bytes);
            std::memset(memory.Data(), 0xAB, memory.Size());
            options.color_memory = memory;
            options.color_destination = memory.Data() + view_bytes;  // one view in
            // By the third round both slots have recorded for this memory and reuse that.
            for (int round = 0; round < 3; ++round) {
                const int64_t recordings = vulkan->GetCounters().recordings;
                const std::vector<RenderOutput> into = backend.RenderBatch(views, {}, options);
                if (round == 2 && &backend == vulkan.get()) {
                    // RGBA8: only the copies move. RGBA32F is composited into the memory
                    // itself, so a recording names its destination; the slots take the three
                    // parts in turn and keep a recording for each (spare recordings).
                    EXPECT_EQ(vulkan->GetCounters().recordings, recordings);
                }
                for (size_t i = 0; i < views.size(); ++i) {
                    SCOPED_TRACE("view " + std::to_string(i));
                    EXPECT_TRUE(into[i].color.IsEmpty());
                    EXPECT_EQ(std::memcmp(memory.Data() + (i + 1) * view_bytes,
                                          images[i].color.AsTensor().RawData(), view_bytes),
                              0);
                }
                EXPECT_TRUE(std::all_of(memory.Data(), memory.Data() + view_bytes,
                                        [](uint8_t b) { return b == 0xAB; }));
                EXPECT_TRUE(std::all_of(memory.Data() + (views.size() + 1) * view_bytes,
                                        memory.Data() + memory.Size(),
                                        [](uint8_t b) { return b == 0xAB; }));
            }
            // One submission to one destination again and again: from the third on (each of
            // the two slots has recorded it once) the recording is submitted as it is.
            const std::vector<camera::PinholeCamera> two(views.begin(), views.begin() + 2);
            for (int call = 0; call < 3; ++call) {
                const int64_t recordings = vulkan->GetCounters().recordings;
                backend.RenderBatch(two, {}, options);
                if (call == 2 && &backend == vulkan.get()) {
                    EXPECT_EQ(vulkan->GetCounters().recordings, recordings);
                }
            }
            EXPECT_EQ(std::memcmp(memory.Data() + 2 * view_bytes,
                                  images[1].color.AsTensor().RawData(), view_bytes),
                      0);
            // Five views (2 + 2 + 1: the last part reuses buffers made for two) land in five
            // views' room, not a byte further.
            std::memset(memory.Data(), 0xAB, memory.Size());
            backend.RenderBatch({views.begin(), views.begin() + 5}, {}, options);
            for (size_t i = 0; i < 5; ++i) {
                EXPECT_EQ(std::memcmp(memory.Data() + (i + 1) * view_bytes,
                                      images[i].color.AsTensor().RawData(), view_bytes),
                          0)
                    << "five views, view " << i;
            }
            EXPECT_TRUE(std::all_of(memory.Data() + 6 * view_bytes, memory.Data() + memory.Size(),
                                    [](uint8_t b) { return b == 0xAB; }));
            // As many views as the (rounded-up) memory holds fit from its start, not from
            // the second view's place.
            options.color_destination = nullptr;
            const auto most = SlidingViews(static_cast<int>(memory.Size() / view_bytes), 48, 32);
            EXPECT_NO_THROW(backend.RenderBatch(most, {}, options));
            options.color_destination = memory.Data() + view_bytes;
            try {
                backend.RenderBatch(most, {}, options);
                ADD_FAILURE() << most.size() << " views at one view's offset were accepted";
            } catch (const core::Open3DError& e) {
                EXPECT_NE(std::string(e.what()).find("do not fit in the batch memory"),
                          std::string::npos)
                    << e.what();
            }
        });
    // One import per block (two blocks: float32 and uint8); the first was dropped by the
    // first submission after its memory went out of scope.
    EXPECT_EQ(vulkan->GetCounters().host_imports, imports ? 2 : 0);
    EXPECT_EQ(vulkan->GetCounters().host_import_releases, imports ? 1 : 0);
}

TEST_F(SubmissionPath, FramesInFlightSurviveAResizeAndASceneChange) {
    // Two frames on the GPU at once: the first of the old scene at one size, the second of a
    // moved scene at another. The old scene's buffers must outlive the first frame (deferred
    // release), and each frame must equal what a fresh backend renders.
    const t::geometry::PointCloud first_scene = CreateDefaultGaussianSplatScene();
    t::geometry::PointCloud second_scene = first_scene;
    second_scene.Translate(Eigen::Vector3d(0.3, 0.1, 0.0));
    const camera::PinholeCamera big = GetDefaultSceneCamera(64, 48);
    const camera::PinholeCamera small = GetDefaultSceneCamera(40, 30);
    auto backend = MakeBackend();
    backend->SetFramesInFlight(2);
    BatchOptions all;
    all.expected_depth = all.median_depth = true;  // as Render's default
    backend->SetScene(first_scene);
    const uint64_t first = backend->SubmitBatch({big}, {}, all);
    backend->SetScene(second_scene);
    const uint64_t second = backend->SubmitBatch({small}, {}, all);
    // Both slots hold uncollected frames.
    EXPECT_THROW(backend->SubmitBatch({small}, {}), core::Open3DError);
    const RenderOutput second_out = backend->WaitBatch(second)[0];
    const RenderOutput first_out = backend->WaitBatch(first)[0];
    EXPECT_THROW(backend->WaitBatch(first), core::Open3DError);
    auto fresh = MakeBackend();
    fresh->SetScene(first_scene);
    {
        SCOPED_TRACE("first frame");
        ExpectSameImages(first_out, fresh->Render(big, {}));
    }
    fresh->SetScene(second_scene);
    {
        SCOPED_TRACE("second frame");
        ExpectSameImages(second_out, fresh->Render(small, {}));
    }
    EXPECT_FALSE(first_out.color.AsTensor() == fresh->Render(big, {}).color.AsTensor());
    // The frames in flight at SetScene kept the scene's four buffers alive.
    EXPECT_EQ(backend->GetCounters().deferred_releases, 4);
    EXPECT_THROW(backend->SetFramesInFlight(0), core::Open3DError);
    backend->SetFramesInFlight(3);
    EXPECT_EQ(backend->GetFramesInFlight(), 3);
    ExpectSameImages(backend->Render(small, {}), fresh->Render(small, {}));
}

// The tally itself, without a device: a dispatch after a barrier starts a new dependent step,
// dispatches between two barriers are one step, and an inner tally counts alone.
TEST(CommandTally, CountsDispatchesBarriersAndDependentSteps) {
    using vulkan::CommandTally;
    CommandTally::NoteDispatch();  // no tally: nothing counted, nothing breaks
    const CommandTally outer;
    CommandTally::NoteDispatch();
    CommandTally::NoteDispatch();
    CommandTally::NoteBarrier();
    CommandTally::NoteBarrier();
    CommandTally::NoteDispatch();
    {
        const CommandTally inner;
        CommandTally::NoteBarrier();
        CommandTally::NoteDispatch();
        EXPECT_EQ(inner.Counts().dispatches, 1);
        EXPECT_EQ(inner.Counts().barriers, 1);
        EXPECT_EQ(inner.Counts().dependent_dispatches, 1);
    }
    CommandTally::NoteDispatch();  // no barrier since the outer tally's last dispatch
    EXPECT_EQ(outer.Counts().dispatches, 4);
    EXPECT_EQ(outer.Counts().barriers, 2);
    EXPECT_EQ(outer.Counts().dependent_dispatches, 2);
}

// A frame reports the dispatches of its recording: the same for a fresh recording, one
// submitted again and each view of a batch (whose recording holds every view's dispatches).
TEST_F(SubmissionPath, DispatchCountsAreTheRecordingsPerView) {
    auto backend = MakeBackend();
    backend->SetScene(CreateDefaultGaussianSplatScene());
    const auto views = SlidingViews(3, 48, 32);
    // Per-tile bins: projection, bin scan, emit, bin sort, composite, each waiting for the
    // one before.
    RenderConfig bins;
    bins.sort_mode = SortMode::kExactTileBins;
    const RenderOutput binned = backend->Render(views[0], bins);
    EXPECT_EQ(binned.stats.dispatches, 5);
    EXPECT_EQ(binned.stats.dependent_dispatches, 5);
    // The default, the global sorts: projection, a depth sort of four scatters (the
    // multi-pass sort: more, and a histogram), the scan, cut and emit (one chained dispatch
    // where the sorts run the one sweep), a tile sort of one or more passes, tile ranges
    // (written by the tile sort's last pass in the chained frame), composite.
    const RenderOutput first = backend->Render(views[0], {});
    EXPECT_GE(first.stats.dispatches, 8);
    EXPECT_GE(first.stats.dependent_dispatches, 8);
    EXPECT_LE(first.stats.dependent_dispatches, first.stats.dispatches);
    for (int i = 0; i < 3; ++i) {  // each frame slot records once, then submits again
        const RenderOutput again = backend->Render(views[1], {});
        EXPECT_EQ(again.stats.dispatches, first.stats.dispatches);
        EXPECT_EQ(again.stats.dependent_dispatches, first.stats.dependent_dispatches);
    }
    for (const RenderOutput& view : backend->RenderBatch(views, {}, BatchOptions{})) {
        EXPECT_EQ(view.stats.dispatches, first.stats.dispatches);
        // Each view of a batch waits for the one before: one barrier more per view.
        EXPECT_GE(view.stats.dependent_dispatches, first.stats.dependent_dispatches);
    }
}

TEST_F(SubmissionPath, TileBinsRenderTheDefaultImagesOnBothPaths) {
    // Both exact orders are the reference's (ties by splat index), so the images agree bit
    // for bit: one submission, a batch, and the viewer's stage path, whose composite reads
    // the ranges the bins left in its state, also when the geometry is reused.
    auto backend = MakeBackend();
    backend->SetScene(CreateDefaultGaussianSplatScene());
    RenderConfig bins;
    bins.sort_mode = SortMode::kExactTileBins;
    bins.background = Eigen::Vector3d(0.1, 0.2, 0.3);
    RenderConfig sorts = bins;
    sorts.sort_mode = SortMode::kExact;
    const auto views = SlidingViews(2, 72, 40);
    const RenderOutput want = backend->Render(views[0], sorts);
    ExpectSameImages(backend->Render(views[0], bins), want);
    BatchOptions with_depths;
    with_depths.expected_depth = true;
    with_depths.median_depth = true;
    const std::vector<RenderOutput> batch = backend->RenderBatch(views, bins, with_depths);
    ExpectSameImages(batch.at(0), want);
    ExpectSameImages(batch.at(1), backend->Render(views[1], sorts));
    for (int frame = 0; frame < 2; ++frame) {  // the second reuses the geometry stage
        backend->RenderGeometryStage(views[0], bins);
        RenderOutput staged;
        backend->RenderCompositeStage(staged);
        EXPECT_TRUE(staged.color.AsTensor() == want.color.AsTensor()) << "frame " << frame;
    }
}

}  // namespace
}  // namespace tests
}  // namespace open3d
