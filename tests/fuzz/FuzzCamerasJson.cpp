// libFuzzer harness for the cameras.json parser: any text ends in views or an Open3DError.
#include <cstdint>
#include <string>

#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const auto views = open3d::camera::ParseCamerasJson(text, "fuzz.json");
        for (const auto& view : views) view.camera.Validate();
    } catch (const open3d::core::Open3DError&) {
    }
    return 0;
}
