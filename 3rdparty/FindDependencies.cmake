# Every dependency comes from a Debian 12 package (scripts/setup.sh installs them).
# Versions seen on Debian 12: fmt 9.1, Eigen 3.4, nlohmann-json 3.11, CLI11 2.3,
# libpng 1.6, GoogleTest 1.12, Google Benchmark 1.7. No sources are vendored here.

find_package(Threads REQUIRED)
find_package(fmt 9 REQUIRED)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(nlohmann_json 3 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(PNG REQUIRED)
# Compressed splat formats (t/io): zlib 1.2.13 (gzip SPZ, deflate in zip), zstd 1.5.4 (SPZ
# v4 streams), libwebp 1.2.4 (SOG images). Debian ships no CMake config for webp.
find_package(ZLIB REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(ZSTD REQUIRED IMPORTED_TARGET libzstd)
pkg_check_modules(WEBP REQUIRED IMPORTED_TARGET libwebp)
# H.264 videos (t/io/H264VideoWriter.h): libx264 0.164 (libx264-dev); the tests decode what it
# wrote with Cisco's openh264 2.3 (libopenh264-dev), a decoder independent of the encoder.
pkg_check_modules(X264 REQUIRED IMPORTED_TARGET x264)

# Eigen's headers are included as SYSTEM through its imported target already.
if(OPEN3D_BUILD_TESTS)
  find_package(GTest REQUIRED)
  pkg_check_modules(OPENH264 REQUIRED IMPORTED_TARGET openh264)
endif()
if(OPEN3D_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()

# Vulkan compute backend: loader + headers (libvulkan-dev 1.3.239), and the shader tools
# (glslang-tools 12, spirv-cross) used by cmake/CompileShaders.cmake.
find_package(Vulkan REQUIRED)
find_program(GLSLANG_VALIDATOR glslangValidator REQUIRED)
find_program(SPIRV_CROSS spirv-cross REQUIRED)

# Filament integration (libfilament-dev + libfilament-tools 1.9.25, libglfw3-dev 3.3.8,
# libgl-dev for the GL headers, libegl-dev for headless EGL; GL entry points are loaded
# through GLFW or EGL at run time).
find_package(filament 1.9 REQUIRED CONFIG)
# The EGL platform declares Filament's private OpenGLPlatform as 1.9.25 lays it out
# (filament/FilamentOpenGLPlatform.h): another version may order its virtual functions
# differently.
if(NOT filament_VERSION VERSION_EQUAL 1.9.25)
  message(FATAL_ERROR "Filament ${filament_VERSION} found; 1.9.25 is needed (Debian 12's "
    "libfilament-dev): FilamentOpenGLPlatform.h mirrors its OpenGLPlatform")
endif()
find_package(glfw3 3.3 REQUIRED)
find_path(OPENGL_GLEXT_INCLUDE_DIR GL/glext.h REQUIRED)
find_path(EGL_INCLUDE_DIR EGL/egl.h REQUIRED)
find_library(EGL_LIBRARY EGL REQUIRED)
find_program(FILAMENT_MATC matc REQUIRED)
