// filament::backend::OpenGLPlatform as Filament 1.9.25 (the Debian package) defines it: the
// base of an OpenGL platform that Engine::create accepts. The package ships no header for it
// (it is private in Filament's tree), so it is declared here. Only the order of the virtual
// functions matters, and it was read from the vtable of PlatformGLX in
// libfilament_backend.so.1.9.25 (docs/filament.md "Headless: the EGL platform"); every
// function is exported there. Include only in EglPlatform.cpp; the CMake check pins 1.9.25.
#pragma once

#include <backend/DriverEnums.h>
#include <backend/Platform.h>

#include <cstdint>

namespace filament {
namespace backend {

/// An image handed to a Stream (Filament's private AcquiredImage). Its fields matter only to
/// streams, which the Open3D platforms do not offer.
struct AcquiredImage {
    void* image = nullptr;
    void (*callback)(void* image, void* user) = nullptr;
    void* user_data = nullptr;
};

class OpenGLPlatform : public DefaultPlatform {
protected:
    /// Filament's OpenGL driver on the context current on the calling (driver) thread.
    static Driver* createDefaultDriver(OpenGLPlatform* platform, void* shared_context);

public:
    ~OpenGLPlatform() noexcept override;
    virtual void terminate() noexcept = 0;
    virtual SwapChain* createSwapChain(void* native_window, uint64_t& flags) noexcept = 0;
    virtual SwapChain* createSwapChain(uint32_t width, uint32_t height,
                                       uint64_t& flags) noexcept = 0;
    virtual void destroySwapChain(SwapChain* swap_chain) noexcept = 0;
    virtual void createDefaultRenderTarget(uint32_t& framebuffer, uint32_t& colorbuffer,
                                           uint32_t& depthbuffer) noexcept;
    virtual void makeCurrent(SwapChain* draw, SwapChain* read) noexcept = 0;
    virtual void commit(SwapChain* swap_chain) noexcept = 0;
    virtual void setPresentationTime(int64_t presentation_time_ns) noexcept = 0;
    virtual bool canCreateFence() noexcept;
    virtual Fence* createFence() noexcept = 0;
    virtual void destroyFence(Fence* fence) noexcept = 0;
    virtual FenceStatus waitFence(Fence* fence, uint64_t timeout) noexcept = 0;
    virtual Stream* createStream(void* native_stream) noexcept = 0;
    virtual void destroyStream(Stream* stream) noexcept = 0;
    virtual void attach(Stream* stream, intptr_t texture_name) noexcept = 0;
    virtual void detach(Stream* stream) noexcept = 0;
    virtual void updateTexImage(Stream* stream, int64_t* timestamp) noexcept = 0;
    virtual ExternalTexture* createExternalTextureStorage() noexcept = 0;
    virtual void reallocateExternalStorage(ExternalTexture* texture, uint32_t width,
                                           uint32_t height, TextureFormat format) noexcept = 0;
    virtual void destroyExternalTextureStorage(ExternalTexture* texture) noexcept = 0;
    virtual AcquiredImage transformAcquiredImage(AcquiredImage source) noexcept;
    virtual bool setExternalImage(void* external_image, void* texture) noexcept;
    virtual void retainExternalImage(void* external_image) noexcept;
    virtual void releaseExternalImage(void* external_image) noexcept;
    virtual void createExternalImageTexture(void* texture) noexcept;
    virtual void destroyExternalImage(void* texture) noexcept;
};

}  // namespace backend
}  // namespace filament
