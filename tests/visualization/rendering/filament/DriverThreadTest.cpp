// FilamentEngine::RunOnDriverThread (FilamentDriverThread.h): on EGL and on GLX an action
// runs on Filament's driver thread with a GL context current, at its place in Filament's
// command stream: after a texture upload issued before it (it reads the uploaded bytes back),
// and before an action issued after it.
#include <gtest/gtest.h>

#include <filament/Engine.h>
#include <filament/Texture.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <thread>
#include <vector>

#include "TestUtility.h"
#include "open3d/visualization/rendering/filament/FilamentDriverThread.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanBackendRegistry.h"

namespace open3d {
namespace tests {
namespace {

namespace rendering = visualization::rendering;

void CheckActionsRunInStreamOrder(rendering::GlPlatform platform) {
    const std::string reason = rendering::FilamentUnavailableReason(platform);
    if (!reason.empty()) OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE(reason);
    rendering::FilamentEngine engine(platform);
    ASSERT_TRUE(engine.CanRunOnDriverThread()) << engine.DriverThreadUnavailableReason();
    const rendering::GlFunctions& gl = engine.GetGl();
    filament::Engine& e = engine.GetEngine();

    // A 4x4 RGBA8 texture of ours, zeroed, then imported into Filament.
    constexpr int kSide = 4;
    constexpr size_t kBytes = kSide * kSide * 4;
    GLuint id = 0;
    gl.CreateTextures(GL_TEXTURE_2D, 1, &id);
    gl.TextureStorage2D(id, 1, GL_RGBA8, kSide, kSide);
    const std::vector<uint8_t> zeros(kBytes, 0);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl.TextureSubImage2D(id, 0, 0, 0, kSide, kSide, GL_RGBA, GL_UNSIGNED_BYTE, zeros.data());
    gl.Finish();
    filament::Texture* texture = filament::Texture::Builder()
                                     .width(kSide)
                                     .height(kSide)
                                     .levels(1)
                                     .sampler(filament::Texture::Sampler::SAMPLER_2D)
                                     .format(filament::Texture::InternalFormat::RGBA8)
                                     .import(intptr_t(id))
                                     .build(e);
    ASSERT_NE(texture, nullptr);

    // Filament uploads these bytes on its thread; the action, issued after, reads them back.
    auto* upload = new std::vector<uint8_t>(kBytes);
    for (size_t i = 0; i < kBytes; ++i) (*upload)[i] = uint8_t(7 * i + 1);
    const std::vector<uint8_t> expected = *upload;
    texture->setImage(
        e, 0,
        filament::Texture::PixelBufferDescriptor(
            upload->data(), kBytes, filament::Texture::Format::RGBA, filament::Texture::Type::UBYTE,
            [](void*, size_t, void* user) { delete static_cast<std::vector<uint8_t>*>(user); },
            upload));

    struct Seen {
        std::thread::id thread;
        bool context = false;
        std::vector<uint8_t> bytes;
    };
    std::vector<int> order;
    Seen first, second;
    ASSERT_TRUE(engine.RunOnDriverThread([&] {
        order.push_back(1);
        first.thread = std::this_thread::get_id();
        first.context = gl.GetString(GL_VERSION) != nullptr;
        first.bytes.assign(kBytes, 0);
        gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
        gl.GetTextureImage(id, 0, GL_RGBA, GL_UNSIGNED_BYTE, GLsizei(kBytes), first.bytes.data());
    }));
    ASSERT_TRUE(engine.RunOnDriverThread([&] {
        order.push_back(2);
        second.thread = std::this_thread::get_id();
        second.context = gl.GetString(GL_VERSION) != nullptr;
    }));
    EXPECT_TRUE(order.empty()) << "an action ran before Filament's stream was flushed";
    engine.FlushAndWait();

    EXPECT_EQ(order, (std::vector<int>{1, 2}));
    EXPECT_NE(first.thread, std::this_thread::get_id());
    EXPECT_EQ(first.thread, second.thread);
    EXPECT_TRUE(first.context);
    EXPECT_TRUE(second.context);
    EXPECT_EQ(first.bytes, expected) << "the action ran before the upload issued before it";

    e.destroy(texture);
    engine.FlushAndWait();
    engine.MakeContextCurrent();
    gl.DeleteTextures(1, &id);
}

TEST(FilamentDriverThread, ActionsRunInStreamOrderOnFilamentsThreadOnEgl) {
    CheckActionsRunInStreamOrder(rendering::GlPlatform::kEgl);
}

// NVIDIA's Vulkan driver ends the GPU's EGL display when the loader unloads it, i.e. when the
// process's last Vulkan instance goes (docs/environment-notes.md "NVIDIA GPUs"); the engine
// keeps the drivers loaded. A Vulkan backend made and destroyed after the engine must leave
// its contexts usable: on the H100 this threw "eglMakeCurrent failed" before the fix.
TEST(FilamentDriverThread, EglContextsOutliveAVulkanBackend) {
    const std::string reason = rendering::FilamentUnavailableReason(rendering::GlPlatform::kEgl);
    if (!reason.empty()) OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE(reason);
    rendering::FilamentEngine engine(rendering::GlPlatform::kEgl);
    rendering::vulkan::RegisterVulkanBackend();
    for (int i = 0; i < 2; ++i) {
        auto backend = rendering::CreateGaussianSplatBackend("vulkan");
        ASSERT_NE(backend, nullptr);
    }
    EXPECT_NO_THROW(engine.MakeContextCurrent());
    EXPECT_NE(engine.GetGl().GetString(GL_VERSION), nullptr);
    bool ran = false;
    engine.RunOnDriverThread([&] { ran = engine.GetGl().GetString(GL_VERSION) != nullptr; });
    engine.FlushAndWait();
    EXPECT_TRUE(ran) << "Filament's thread lost its context";
}

TEST(FilamentDriverThread, ActionsRunInStreamOrderOnFilamentsThreadOnGlx) {
    // The suite's headless run (filament.egl_headless, no DISPLAY) is about EGL; the run with
    // an X server checks GLX (and fails in CI where that server is missing).
    if (rendering::ResolveGlPlatform(rendering::GlPlatform::kAuto) != rendering::GlPlatform::kGlx) {
        return;
    }
    CheckActionsRunInStreamOrder(rendering::GlPlatform::kGlx);
}

// The hook reads Filament's private engine; where what it finds is not an OpenGL driver's
// command stream it must refuse rather than queue into arbitrary memory.
TEST(FilamentDriverThread, HookRefusesWhatIsNotFilamentsCommandStream) {
    struct NotADriver {
        virtual ~NotADriver() = default;
    };
    NotADriver not_a_driver;
    alignas(16) std::array<unsigned char, 4096> fake_engine{};
    auto& engine = *reinterpret_cast<filament::Engine*>(fake_engine.data());
    const rendering::DriverThreadHook empty(engine);
    EXPECT_FALSE(empty.Available());
    EXPECT_NE(empty.Why().find("no driver"), std::string::npos) << empty.Why();

    void* driver = &not_a_driver;
    std::memcpy(fake_engine.data() + 0xa50, &driver, sizeof(driver));
    const rendering::DriverThreadHook wrong(engine);
    EXPECT_FALSE(wrong.Available());
    EXPECT_NE(wrong.Why().find("not Filament 1.9.25's OpenGL driver"), std::string::npos)
        << wrong.Why();
    EXPECT_FALSE(wrong.Run([] {}));
}

}  // namespace
}  // namespace tests
}  // namespace open3d
