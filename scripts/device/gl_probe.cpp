// Prints what the OpenGL driver behind a GLFW (GLX) context offers for sharing images and
// semaphores with Vulkan: vendor, renderer, version, the EXT_external_objects extensions and
// the device and driver UUIDs (compare with `vulkaninfo`). Built and carried by
// scripts/device/filament.sh; exits 1 when no context can be made.
#include <GLFW/glfw3.h>

#include <cstdio>
#include <cstring>

using GetStringi = const unsigned char* (*)(unsigned, unsigned);
using GetIntegerv = void (*)(unsigned, int*);
using GetUnsignedBytei = void (*)(unsigned, unsigned, unsigned char*);

int main() {
    if (!glfwInit()) {
        std::fprintf(stderr, "gl_probe: glfwInit failed (no X display?)\n");
        return 1;
    }
    glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_ALPHA_BITS, 0);
    GLFWwindow* window = glfwCreateWindow(64, 64, "gl_probe", nullptr, nullptr);
    if (!window) {
        const char* why = nullptr;
        glfwGetError(&why);
        std::fprintf(stderr, "gl_probe: no OpenGL 4.5 core context: %s\n", why ? why : "?");
        return 1;
    }
    glfwMakeContextCurrent(window);
    auto get_string =
        reinterpret_cast<const unsigned char* (*)(unsigned)>(glfwGetProcAddress("glGetString"));
    auto get_stringi = reinterpret_cast<GetStringi>(glfwGetProcAddress("glGetStringi"));
    auto get_integerv = reinterpret_cast<GetIntegerv>(glfwGetProcAddress("glGetIntegerv"));
    std::printf("GL_VENDOR   %s\nGL_RENDERER %s\nGL_VERSION  %s\n", get_string(0x1F00),
                get_string(0x1F01), get_string(0x1F02));
    int count = 0;
    get_integerv(0x821D /* GL_NUM_EXTENSIONS */, &count);
    const char* wanted[] = {"GL_EXT_memory_object", "GL_EXT_memory_object_fd", "GL_EXT_semaphore",
                            "GL_EXT_semaphore_fd"};
    for (const char* name : wanted) {
        bool found = false;
        for (int i = 0; i < count && !found; ++i) {
            found = std::strcmp(reinterpret_cast<const char*>(get_stringi(0x1F03, i)), name) == 0;
        }
        std::printf("%-24s %s\n", name, found ? "yes" : "no");
    }
    auto get_uuid =
        reinterpret_cast<GetUnsignedBytei>(glfwGetProcAddress("glGetUnsignedBytei_vEXT"));
    auto get_uuid0 = reinterpret_cast<void (*)(unsigned, unsigned char*)>(
        glfwGetProcAddress("glGetUnsignedBytevEXT"));
    if (get_uuid && get_uuid0) {
        unsigned char uuid[16];
        get_uuid(0x9597 /* GL_DEVICE_UUID_EXT */, 0, uuid);
        std::printf("device UUID ");
        for (unsigned char b : uuid) std::printf("%02x", b);
        get_uuid0(0x9598 /* GL_DRIVER_UUID_EXT */, uuid);
        std::printf("\ndriver UUID ");
        for (unsigned char b : uuid) std::printf("%02x", b);
        std::printf("\n");
    }
    glfwDestroyWindow(window);
    glfwTerminate();
    return 0;
}
