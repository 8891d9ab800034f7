#include "open3d/visualization/rendering/filament/SplatTargets.h"

#include <GLFW/glfw3.h>
#include <filament/Engine.h>
#include <filament/Texture.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <future>
#include <string>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatInterop.h"

namespace open3d {
namespace visualization {
namespace rendering {

namespace {

// The splat depth counts where at least half the pixel is covered (as GPU depth merge).
constexpr float kDepthMinAlpha = 0.5f;

filament::Texture* ImportTexture(filament::Engine& engine, uint32_t gl_name, uint32_t width,
                                 uint32_t height, filament::Texture::InternalFormat format,
                                 filament::Texture::Usage usage) {
    return filament::Texture::Builder()
        .width(width)
        .height(height)
        .levels(1)
        .sampler(filament::Texture::Sampler::SAMPLER_2D)
        .format(format)
        .usage(usage)
        .import(static_cast<intptr_t>(gl_name))
        .build(engine);
}

}  // namespace

SplatSharing ParseSplatSharing(const std::string& text) {
    if (text == "auto") return SplatSharing::kAuto;
    if (text == "zero-copy") return SplatSharing::kZeroCopy;
    if (text == "host-copy") return SplatSharing::kHostCopy;
    core::ThrowError("unknown splat sharing mode '{}' (use auto, zero-copy or host-copy)", text);
}

std::string ZeroCopyUnavailableReason(const FilamentEngine& engine,
                                      const GaussianSplatBackend& backend) {
    const vulkan::InteropSupport vk = vulkan::QueryInteropSupport(backend);
    if (!vk.external_memory_fd) {
        return fmt::format(
            "the '{}' backend cannot export memory (needs the Vulkan backend "
            "with VK_KHR_external_memory_fd)",
            backend.GetName());
    }
    const GlFunctions& gl = engine.GetGl();
    if (!gl.HasMemoryObjectFd()) {
        return "the OpenGL driver lacks GL_EXT_memory_object_fd";
    }
    if (gl.DeviceUuid() != vk.device_uuid || gl.DriverUuid() != vk.driver_uuid) {
        return "OpenGL and Vulkan run on different devices or drivers (UUIDs differ)";
    }
    return {};
}

SplatTargets::SplatTargets(FilamentEngine& engine, GaussianSplatBackend& backend, uint32_t width,
                           uint32_t height, SplatSharing sharing)
    : engine_(engine), width_(width), height_(height) {
    if (width == 0 || height == 0)
        core::ThrowError("splat targets: empty size {}x{}", width, height);
    engine_.MakeContextCurrent();
    std::string why;
    if (sharing != SplatSharing::kHostCopy) why = ZeroCopyUnavailableReason(engine, backend);
    if (sharing == SplatSharing::kZeroCopy && !why.empty()) {
        core::ThrowError("zero-copy splat images are unavailable: {}", why);
    }
    // Once per process: the choice and its reason do not change.
    static bool logged = false;
    if (sharing != SplatSharing::kHostCopy && why.empty()) {
        CreateZeroCopy(backend);
        if (!logged) {
            core::LogInfo(
                "Splat images are shared zero-copy: Vulkan memory imported into OpenGL ({}), "
                "no host copies",
                engine.GetGl().Describe());
        }
    } else {
        if (sharing == SplatSharing::kAuto && !logged) {
            core::LogInfo("Splat images use host copies: {}", why);
        }
        CreateHostCopy();
    }
    logged = true;
}

void SplatTargets::CreateZeroCopy(GaussianSplatBackend& backend) {
    interop_ = std::make_unique<vulkan::InteropTargets>(backend, width_, height_);
    const GlFunctions& gl = engine_.GetGl();
    const vulkan::ExportedImageMemory exports[3] = {
        interop_->ExportColor(), interop_->ExportDepth(), interop_->ExportMeshColor()};
    const GLenum formats[3] = {GL_RGBA16F, GL_DEPTH_COMPONENT32F, GL_RGBA8};
    uint32_t* names[3] = {&gl_color_, &gl_depth_, &gl_mesh_color_};
    gl.CreateMemoryObjectsEXT(3, gl_memory_);
    for (int i = 0; i < 3; ++i) {
        const GLint dedicated = exports[i].dedicated ? GL_TRUE : GL_FALSE;
        gl.MemoryObjectParameterivEXT(gl_memory_[i], GL_DEDICATED_MEMORY_OBJECT_EXT, &dedicated);
        // GL owns the descriptor after a successful import.
        gl.ImportMemoryFdEXT(gl_memory_[i], exports[i].size, GL_HANDLE_TYPE_OPAQUE_FD_EXT,
                             exports[i].fd);
        gl.CreateTextures(GL_TEXTURE_2D, 1, names[i]);
        gl.TextureStorageMem2DEXT(*names[i], 1, formats[i], static_cast<GLsizei>(width_),
                                  static_cast<GLsizei>(height_), gl_memory_[i], 0);
    }
    gl.CheckError("importing the Vulkan splat images (glImportMemoryFdEXT)");
    // Filament's context must see complete objects.
    gl.Finish();
    ImportIntoFilament();
    mesh_color_texture_ = ImportTexture(
        engine_.GetEngine(), gl_mesh_color_, width_, height_,
        filament::Texture::InternalFormat::RGBA8,
        filament::Texture::Usage::COLOR_ATTACHMENT | filament::Texture::Usage::SAMPLEABLE);
    SetUpGpuHandover(backend);
}

void SplatTargets::SetUpGpuHandover(GaussianSplatBackend& backend) {
    const GlFunctions& gl = engine_.GetGl();
    // On EGL by default where both drivers can (run on NVIDIA's); on GLX only when asked
    // (OPEN3D_GL_VK_SEMAPHORES=1): it has not run there with NVIDIA's GL. =0 keeps the host
    // waits, =mesh the GL-to-Vulkan one alone, the host waiting for the composite before GL's
    // compose view (docs/filament.md "Synchronisation").
    const char* env = std::getenv("OPEN3D_GL_VK_SEMAPHORES");
    const bool asked = env != nullptr && *env != '\0';
    const bool glx = engine_.GetPlatform() == GlPlatform::kGlx;
    const std::string mode = asked ? env : (glx ? "0" : "1");
    if (mode != "0" && mode != "1" && mode != "mesh") {
        core::ThrowError("OPEN3D_GL_VK_SEMAPHORES is '{}': 0, 1 or mesh", mode);
    }
    splats_drawn_handover_ = mode == "1";
    std::string why;
    if (mode == "0") {
        why = asked ? "OPEN3D_GL_VK_SEMAPHORES=0"
                    : "on GLX it is opt-in (OPEN3D_GL_VK_SEMAPHORES=1): it has not run there "
                      "on a GPU yet";
    } else if (!engine_.CanRunOnDriverThread()) {
        why = engine_.DriverThreadUnavailableReason();
    } else if (!vulkan::QueryInteropSupport(backend).external_semaphore_fd) {
        why = "the Vulkan device cannot export semaphores (VK_KHR_external_semaphore_fd)";
    } else if (!gl.HasSemaphoreFd()) {
        why = "the OpenGL driver lacks GL_EXT_semaphore_fd";
    }
    if (why.empty()) {
        const int fds[2] = {interop_->ExportMeshDrawnSemaphore(),
                            interop_->ExportSplatsDrawnSemaphore()};
        GLuint names[2] = {0, 0};
        gl.GenSemaphoresEXT(2, names);
        // GL owns each descriptor after a successful import.
        for (int i = 0; i < 2; ++i) {
            gl.ImportSemaphoreFdEXT(names[i], GL_HANDLE_TYPE_OPAQUE_FD_EXT, fds[i]);
        }
        gl.CheckError("importing the hand-over semaphores (glImportSemaphoreFdEXT)");
        gl.Finish();
        gl_mesh_drawn_ = names[0];
        gl_splats_drawn_ = names[1];
    }
    static bool logged = false;
    if (!logged) {
        logged = true;
        if (why.empty()) {
            core::LogInfo("GL hands the mesh view to Vulkan with a semaphore: no host wait");
        } else {
            core::LogInfo("GL hands the mesh view to Vulkan through a host wait: {}", why);
        }
    }
}

bool SplatTargets::SignalMeshDrawn() {
    if (gl_mesh_drawn_ == 0) return false;
    const GlFunctions gl = engine_.GetGl();
    const GLuint semaphore = gl_mesh_drawn_;
    const GLuint textures[2] = {gl_depth_, gl_mesh_color_};
    std::promise<void> flushed;
    std::future<void> done = flushed.get_future();
    // The composite acquires both images in GENERAL layout (GaussianSplatInterop.cpp).
    engine_.RunOnDriverThread([gl, semaphore, textures, &flushed] {
        const GLenum layouts[2] = {GL_LAYOUT_GENERAL_EXT, GL_LAYOUT_GENERAL_EXT};
        gl.SignalSemaphoreEXT(semaphore, 0, nullptr, 2, textures, layouts);
        gl.Flush();  // a signal reaches the GPU only when flushed
        flushed.set_value();
    });
    engine_.Flush();
    done.wait();  // Filament's thread issued what came before: host work, not GPU time
    mesh_drawn_signaled_ = true;
    return true;
}

bool SplatTargets::WaitSplatsDrawn() {
    if (!splats_drawn_signaled_) return false;
    splats_drawn_signaled_ = false;
    const GlFunctions gl = engine_.GetGl();
    const GLuint semaphore = gl_splats_drawn_;
    // The composite released colour and depth to GL in GENERAL layout (GaussianSplatInterop).
    const GLuint textures[2] = {gl_color_, gl_depth_};
    engine_.RunOnDriverThread([gl, semaphore, textures] {
        const GLenum layouts[2] = {GL_LAYOUT_GENERAL_EXT, GL_LAYOUT_GENERAL_EXT};
        gl.WaitSemaphoreEXT(semaphore, 0, nullptr, 2, textures, layouts);
    });
    return true;
}

void SplatTargets::CreateHostCopy() {
    const GlFunctions& gl = engine_.GetGl();
    gl.CreateTextures(GL_TEXTURE_2D, 1, &gl_color_);
    gl.TextureStorage2D(gl_color_, 1, GL_RGBA16F, static_cast<GLsizei>(width_),
                        static_cast<GLsizei>(height_));
    gl.CreateTextures(GL_TEXTURE_2D, 1, &gl_depth_);
    gl.TextureStorage2D(gl_depth_, 1, GL_DEPTH_COMPONENT32F, static_cast<GLsizei>(width_),
                        static_cast<GLsizei>(height_));
    gl.CheckError("creating the host-copy splat textures");
    gl.Finish();
    ImportIntoFilament();
}

void SplatTargets::ImportIntoFilament() {
    filament::Engine& e = engine_.GetEngine();
    color_texture_ =
        ImportTexture(e, gl_color_, width_, height_, filament::Texture::InternalFormat::RGBA16F,
                      filament::Texture::Usage::SAMPLEABLE);
    depth_texture_ = ImportTexture(
        e, gl_depth_, width_, height_, filament::Texture::InternalFormat::DEPTH32F,
        filament::Texture::Usage::DEPTH_ATTACHMENT | filament::Texture::Usage::SAMPLEABLE);
}

SplatTargets::~SplatTargets() {
    filament::Engine& e = engine_.GetEngine();
    e.destroy(color_texture_);
    e.destroy(depth_texture_);
    if (mesh_color_texture_ != nullptr) e.destroy(mesh_color_texture_);
    // Filament deletes imported textures lazily on its thread; the GL names and memory
    // must outlive that.
    e.flushAndWait();
    engine_.MakeContextCurrent();
    const GlFunctions& gl = engine_.GetGl();
    const GLuint names[3] = {gl_color_, gl_depth_, gl_mesh_color_};
    gl.DeleteTextures(gl_mesh_color_ != 0 ? 3 : 2, names);
    if (gl_memory_[0] != 0) gl.DeleteMemoryObjectsEXT(3, gl_memory_);
    if (gl_mesh_drawn_ != 0) {
        const GLuint semaphores[2] = {gl_mesh_drawn_, gl_splats_drawn_};
        gl.DeleteSemaphoresEXT(2, semaphores);
    }
    gl.Finish();
    interop_.reset();
}

void SplatTargets::Composite(GaussianSplatBackend& backend, const SplatCompositeRequest& request,
                             SplatFrame& frame) {
    if (!interop_) {
        CompositeHostCopy(backend, request, frame);
        return;
    }
    // A signal GL never waited for (a frame that ended before its compose view) is waited
    // for first: a binary semaphore takes one signal per wait.
    WaitSplatsDrawn();
    vulkan::InteropCompositeRequest vk;
    vk.use_scene_depth = request.use_scene_depth;
    vk.scene_near = request.scene_near;
    vk.read_color = request.read_color;
    vk.blend_over_mesh = request.blend_over_mesh;
    vk.read_depth = request.read_depth;
    vk.depth_near = request.depth_near;
    vk.depth_far = request.depth_far;
    vk.wait_mesh_drawn = mesh_drawn_signaled_;
    mesh_drawn_signaled_ = false;  // one wait per signal
    // GL waits for it in WaitSplatsDrawn (a presented frame's compose view).
    vk.signal_splats_drawn = request.presented && splats_drawn_handover_ && gl_splats_drawn_ != 0 &&
                             !request.read_color && !request.blend_over_mesh && !request.read_depth;
    splats_drawn_signaled_ = vk.signal_splats_drawn;
    vulkan::InteropFrame out;
    vulkan::RenderCompositeToInterop(backend, *interop_, vk, out);
    frame.color = std::move(out.color);
    frame.blended = std::move(out.blended);
    frame.linear_depth = std::move(out.linear_depth);
    frame.normalized_depth = std::move(out.normalized_depth);
    frame.stats = out.stats;
}

void SplatTargets::CompositeHostCopy(GaussianSplatBackend& backend,
                                     const SplatCompositeRequest& request, SplatFrame& frame) {
    if (request.blend_over_mesh) {
        core::ThrowError("splat targets: the blend over the mesh colour needs zero-copy images");
    }
    engine_.MakeContextCurrent();
    const GlFunctions& gl = engine_.GetGl();
    t::geometry::Image scene_z;
    if (request.use_scene_depth) scene_z = ReadSceneDepth(request.scene_near);
    RenderOutput out;
    CompositeInputs inputs;
    inputs.scene_depth = request.use_scene_depth ? &scene_z : nullptr;
    inputs.expected_depth = request.read_depth;  // what MergeDepthOnHost reads
    inputs.median_depth = false;
    backend.RenderCompositeStage(out, inputs);
    if (out.color.GetRows() != height_ || out.color.GetCols() != width_) {
        core::ThrowError("splat targets are {}x{} but the backend rendered {}x{}", width_, height_,
                         out.color.GetCols(), out.color.GetRows());
    }
    // Rows go up in the image's order (top first), as the Vulkan path writes them: the
    // overlay material flips y for both.
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TextureSubImage2D(gl_color_, 0, 0, 0, static_cast<GLsizei>(width_),
                         static_cast<GLsizei>(height_), GL_RGBA, GL_FLOAT, out.color.Data<float>());
    gl.CheckError("uploading the splat colour (glTextureSubImage2D)");
    gl.Finish();
    if (request.read_depth) {
        MergeDepthOnHost(&out, request.use_scene_depth ? &scene_z : nullptr, request.depth_near,
                         request.depth_far, kDepthMinAlpha, frame.linear_depth,
                         frame.normalized_depth);
    }
    frame.stats = out.stats;
    if (request.read_color) frame.color = std::move(out.color);
}

t::geometry::Image SplatTargets::ReadSceneDepth(float scene_near) {
    engine_.MakeContextCurrent();
    const GlFunctions& gl = engine_.GetGl();
    // GL rows are bottom-first and hold reversed-Z d = near / z (0 = nothing drawn).
    const size_t pixels = size_t(width_) * height_;
    std::vector<float> d(pixels);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.GetTextureImage(gl_depth_, 0, GL_DEPTH_COMPONENT, GL_FLOAT,
                       static_cast<GLsizei>(pixels * sizeof(float)), d.data());
    gl.CheckError("reading the scene depth (glGetTextureImage)");
    t::geometry::Image scene_z(height_, width_, 1, core::Dtype::Float32);
    float* z = scene_z.Data<float>();
    for (uint32_t y = 0; y < height_; ++y) {
        const float* row = d.data() + size_t(height_ - 1 - y) * width_;
        for (uint32_t x = 0; x < width_; ++x) {
            z[size_t(y) * width_ + x] = row[x] > 0.0f ? scene_near / row[x] : 0.0f;
        }
    }
    return scene_z;
}

void SplatTargets::ReadMeshDepth(float scene_near, float depth_near, float depth_far,
                                 SplatFrame& frame) {
    const t::geometry::Image scene_z = ReadSceneDepth(scene_near);
    MergeDepthOnHost(nullptr, &scene_z, depth_near, depth_far, kDepthMinAlpha, frame.linear_depth,
                     frame.normalized_depth);
}

void MergeDepthOnHost(const RenderOutput* splats, const t::geometry::Image* scene_z, float near,
                      float far, float min_alpha, t::geometry::Image& linear,
                      t::geometry::Image& normalized) {
    const t::geometry::Image& shape = splats ? splats->color : *scene_z;
    const int64_t h = shape.GetRows(), w = shape.GetCols();
    linear = t::geometry::Image(h, w, 1, core::Dtype::Float32);
    normalized = t::geometry::Image(h, w, 1, core::Dtype::UInt16);
    const float* color = splats ? splats->color.Data<float>() : nullptr;
    const float* depth = splats ? splats->depth_expected.Data<float>() : nullptr;
    const float* scene = scene_z ? scene_z->Data<float>() : nullptr;
    float* out_z = linear.Data<float>();
    uint16_t* out_u = normalized.Data<uint16_t>();
    for (int64_t i = 0; i < h * w; ++i) {
        float z = INFINITY;
        const float alpha = color ? color[4 * i + 3] : 0.0f;
        if (alpha > 0.0f && alpha >= min_alpha) z = depth[i];
        if (scene && scene[i] > 0.0f) z = std::min(z, scene[i]);
        const bool found = std::isfinite(z);
        const float u = std::clamp((z - near) / (far - near), 0.0f, 1.0f);
        out_z[i] = found ? z : 0.0f;
        out_u[i] = found ? static_cast<uint16_t>(std::lround(u * 65535.0f)) : uint16_t(65535);
    }
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
