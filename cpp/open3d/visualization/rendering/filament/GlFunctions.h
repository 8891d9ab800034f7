// The few OpenGL 4.5 entry points the Filament layer calls itself (texture creation, memory
// objects of GL_EXT_memory_object_fd, host copies), loaded through GLFW (GLX) or EGL from
// the context that is current on the calling thread. Filament keeps its own loader for its own
// context.
#pragma once

#define GLFW_INCLUDE_NONE
#include <GL/gl.h>
#include <GL/glext.h>

#include <array>
#include <cstdint>
#include <string>

namespace open3d {
namespace visualization {
namespace rendering {

struct GlFunctions {
    PFNGLGETSTRINGIPROC GetStringi = nullptr;
    // GL 1.x functions have prototypes in gl.h but no PFN typedefs.
    decltype(&::glGetString) GetString = nullptr;
    decltype(&::glGetIntegerv) GetIntegerv = nullptr;
    decltype(&::glGetError) GetError = nullptr;
    decltype(&::glFinish) Finish = nullptr;
    PFNGLCREATETEXTURESPROC CreateTextures = nullptr;
    decltype(&::glDeleteTextures) DeleteTextures = nullptr;
    PFNGLTEXTURESTORAGE2DPROC TextureStorage2D = nullptr;
    PFNGLTEXTURESUBIMAGE2DPROC TextureSubImage2D = nullptr;
    PFNGLGETTEXTUREIMAGEPROC GetTextureImage = nullptr;
    decltype(&::glPixelStorei) PixelStorei = nullptr;
    // GL_EXT_memory_object, GL_EXT_memory_object_fd (null when the driver lacks them).
    PFNGLCREATEMEMORYOBJECTSEXTPROC CreateMemoryObjectsEXT = nullptr;
    PFNGLDELETEMEMORYOBJECTSEXTPROC DeleteMemoryObjectsEXT = nullptr;
    PFNGLMEMORYOBJECTPARAMETERIVEXTPROC MemoryObjectParameterivEXT = nullptr;
    PFNGLIMPORTMEMORYFDEXTPROC ImportMemoryFdEXT = nullptr;
    PFNGLTEXTURESTORAGEMEM2DEXTPROC TextureStorageMem2DEXT = nullptr;
    PFNGLGETUNSIGNEDBYTEVEXTPROC GetUnsignedBytevEXT = nullptr;
    PFNGLGETUNSIGNEDBYTEI_VEXTPROC GetUnsignedBytei_vEXT = nullptr;
    // GL_EXT_semaphore, GL_EXT_semaphore_fd (null when the driver lacks them).
    PFNGLGENSEMAPHORESEXTPROC GenSemaphoresEXT = nullptr;
    PFNGLDELETESEMAPHORESEXTPROC DeleteSemaphoresEXT = nullptr;
    PFNGLIMPORTSEMAPHOREFDEXTPROC ImportSemaphoreFdEXT = nullptr;
    PFNGLSIGNALSEMAPHOREEXTPROC SignalSemaphoreEXT = nullptr;
    PFNGLWAITSEMAPHOREEXTPROC WaitSemaphoreEXT = nullptr;
    decltype(&::glFlush) Flush = nullptr;
    // Timer queries (core 3.3), for GPU timelines of Filament's frames.
    PFNGLGENQUERIESPROC GenQueries = nullptr;
    PFNGLDELETEQUERIESPROC DeleteQueries = nullptr;
    PFNGLQUERYCOUNTERPROC QueryCounter = nullptr;
    PFNGLGETQUERYOBJECTUI64VPROC GetQueryObjectui64v = nullptr;

    /// glfwGetProcAddress or eglGetProcAddress.
    using ProcLoader = void* (*)(const char* name);
    /// Loads every pointer from the context current on this thread through `get`. Throws
    /// core::Open3DError when a core 4.5 entry point is missing (the extension ones may stay
    /// null).
    static GlFunctions Load(ProcLoader get);

    /// "GL_VENDOR GL_RENDERER, GL_VERSION" of the current context, for log lines.
    std::string Describe() const;
    /// True when the current context lists `name` in GL_EXTENSIONS.
    bool HasExtension(const std::string& name) const;
    /// GL_EXT_memory_object + GL_EXT_memory_object_fd with all their entry points.
    bool HasMemoryObjectFd() const;
    /// GL_EXT_semaphore + GL_EXT_semaphore_fd with all their entry points.
    bool HasSemaphoreFd() const;
    /// GL_DEVICE_UUID_EXT of device 0 and GL_DRIVER_UUID_EXT (zeros without the extension).
    std::array<uint8_t, 16> DeviceUuid() const;
    std::array<uint8_t, 16> DriverUuid() const;

    /// Throws core::Open3DError naming `what` when glGetError reports an error.
    void CheckError(const char* what) const;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
