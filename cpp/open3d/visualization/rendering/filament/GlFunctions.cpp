#include "open3d/visualization/rendering/filament/GlFunctions.h"

#include <cstring>

#include "open3d/core/Exception.h"

namespace open3d {
namespace visualization {
namespace rendering {

namespace {

template <typename T>
void LoadProc(GlFunctions::ProcLoader get, T& pointer, const char* name) {
    pointer = reinterpret_cast<T>(get(name));
}

// A core 4.5 entry point: missing means the context is too old.
template <typename T>
void LoadRequired(GlFunctions::ProcLoader get, T& pointer, const char* name) {
    LoadProc(get, pointer, name);
    if (pointer == nullptr) {
        core::ThrowError("OpenGL: the context lacks {} (need OpenGL 4.5 core)", name);
    }
}

}  // namespace

GlFunctions GlFunctions::Load(ProcLoader get) {
    GlFunctions gl;
    LoadRequired(get, gl.GetStringi, "glGetStringi");
    LoadRequired(get, gl.GetString, "glGetString");
    LoadRequired(get, gl.GetIntegerv, "glGetIntegerv");
    LoadRequired(get, gl.GetError, "glGetError");
    LoadRequired(get, gl.Finish, "glFinish");
    LoadRequired(get, gl.Flush, "glFlush");
    LoadRequired(get, gl.CreateTextures, "glCreateTextures");
    LoadRequired(get, gl.DeleteTextures, "glDeleteTextures");
    LoadRequired(get, gl.TextureStorage2D, "glTextureStorage2D");
    LoadRequired(get, gl.TextureSubImage2D, "glTextureSubImage2D");
    LoadRequired(get, gl.GetTextureImage, "glGetTextureImage");
    LoadRequired(get, gl.PixelStorei, "glPixelStorei");
    LoadRequired(get, gl.GenQueries, "glGenQueries");
    LoadRequired(get, gl.DeleteQueries, "glDeleteQueries");
    LoadRequired(get, gl.QueryCounter, "glQueryCounter");
    LoadRequired(get, gl.GetQueryObjectui64v, "glGetQueryObjectui64v");
    LoadProc(get, gl.CreateMemoryObjectsEXT, "glCreateMemoryObjectsEXT");
    LoadProc(get, gl.DeleteMemoryObjectsEXT, "glDeleteMemoryObjectsEXT");
    LoadProc(get, gl.MemoryObjectParameterivEXT, "glMemoryObjectParameterivEXT");
    LoadProc(get, gl.ImportMemoryFdEXT, "glImportMemoryFdEXT");
    LoadProc(get, gl.TextureStorageMem2DEXT, "glTextureStorageMem2DEXT");
    LoadProc(get, gl.GetUnsignedBytevEXT, "glGetUnsignedBytevEXT");
    LoadProc(get, gl.GetUnsignedBytei_vEXT, "glGetUnsignedBytei_vEXT");
    LoadProc(get, gl.GenSemaphoresEXT, "glGenSemaphoresEXT");
    LoadProc(get, gl.DeleteSemaphoresEXT, "glDeleteSemaphoresEXT");
    LoadProc(get, gl.ImportSemaphoreFdEXT, "glImportSemaphoreFdEXT");
    LoadProc(get, gl.SignalSemaphoreEXT, "glSignalSemaphoreEXT");
    LoadProc(get, gl.WaitSemaphoreEXT, "glWaitSemaphoreEXT");
    return gl;
}

std::string GlFunctions::Describe() const {
    auto text = [this](GLenum name) {
        const GLubyte* value = GetString(name);
        return value ? std::string(reinterpret_cast<const char*>(value)) : std::string("?");
    };
    return text(GL_VENDOR) + " " + text(GL_RENDERER) + ", " + text(GL_VERSION);
}

bool GlFunctions::HasExtension(const std::string& name) const {
    GLint count = 0;
    GetIntegerv(GL_NUM_EXTENSIONS, &count);
    for (GLint i = 0; i < count; ++i) {
        const auto* extension = reinterpret_cast<const char*>(GetStringi(GL_EXTENSIONS, i));
        if (extension != nullptr && name == extension) return true;
    }
    return false;
}

bool GlFunctions::HasMemoryObjectFd() const {
    return HasExtension("GL_EXT_memory_object") && HasExtension("GL_EXT_memory_object_fd") &&
           CreateMemoryObjectsEXT && DeleteMemoryObjectsEXT && MemoryObjectParameterivEXT &&
           ImportMemoryFdEXT && TextureStorageMem2DEXT && GetUnsignedBytevEXT &&
           GetUnsignedBytei_vEXT;
}

bool GlFunctions::HasSemaphoreFd() const {
    return HasExtension("GL_EXT_semaphore") && HasExtension("GL_EXT_semaphore_fd") &&
           GenSemaphoresEXT && DeleteSemaphoresEXT && ImportSemaphoreFdEXT && SignalSemaphoreEXT &&
           WaitSemaphoreEXT;
}

std::array<uint8_t, 16> GlFunctions::DeviceUuid() const {
    std::array<uint8_t, 16> uuid{};
    if (GetUnsignedBytei_vEXT) GetUnsignedBytei_vEXT(GL_DEVICE_UUID_EXT, 0, uuid.data());
    return uuid;
}

std::array<uint8_t, 16> GlFunctions::DriverUuid() const {
    std::array<uint8_t, 16> uuid{};
    if (GetUnsignedBytevEXT) GetUnsignedBytevEXT(GL_DRIVER_UUID_EXT, uuid.data());
    return uuid;
}

void GlFunctions::CheckError(const char* what) const {
    const GLenum error = GetError();
    if (error != GL_NO_ERROR) core::ThrowError("OpenGL: {} failed (error 0x{:04x})", what, error);
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
