#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/PlaceholderBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"

namespace open3d {
namespace visualization {
namespace rendering {

namespace {

struct Registry {
    // Built-ins are added on first use, so static-library linking cannot drop them.
    Registry() {
        factories["cpu"] = [] { return std::make_unique<cpu::CpuBackend>(); };
        factories["placeholder"] = [] { return std::make_unique<PlaceholderBackend>(); };
    }
    std::mutex mutex;
    std::map<std::string, GaussianSplatBackendFactory> factories;
};

Registry& GetRegistry() {
    static Registry registry;
    return registry;
}

}  // namespace

void GaussianSplatBackend::SetScenePool(int64_t, int, const Eigen::Vector3d&,
                                        const Eigen::Vector3d&, bool) {
    core::ThrowError("the '{}' splat backend cannot stream a paged scene (the vulkan backend can)",
                     GetName());
}

void GaussianSplatBackend::ApplyStreamStep(const SplatStreamStep&) {
    core::ThrowError("the '{}' splat backend cannot stream a paged scene (the vulkan backend can)",
                     GetName());
}

RenderOutput GaussianSplatBackend::Render(const camera::PinholeCamera& camera,
                                          const RenderConfig& config,
                                          const CompositeInputs& inputs) {
    RenderGeometryStage(camera, config);
    RenderOutput output;
    RenderCompositeStage(output, inputs);
    return output;
}

void CheckBatchCameras(const std::vector<camera::PinholeCamera>& cameras) {
    for (const camera::PinholeCamera& camera : cameras) {
        if (camera.width != cameras[0].width || camera.height != cameras[0].height) {
            core::ThrowError("RenderBatch: every camera must have one size ({}x{}); one is {}x{}",
                             cameras[0].width, cameras[0].height, camera.width, camera.height);
        }
    }
}

t::geometry::Image ColorToUInt8(const t::geometry::Image& color) {
    const int64_t h = color.GetRows(), w = color.GetCols();
    t::geometry::Image out(h, w, 4, core::Dtype::UInt8);
    const float* src = color.Data<float>();
    uint8_t* dst = out.Data<uint8_t>();
    for (int64_t i = 0; i < h * w * 4; ++i) {
        const float v = std::min(1.0f, std::max(0.0f, src[i]));  // NaN -> 0
        dst[i] = static_cast<uint8_t>(std::lround(v * 255.0f));
    }
    return out;
}

uint8_t* BatchColorDestination(const BatchOptions& options, size_t views, size_t view_bytes) {
    if (!options.color_memory) return options.color_destination;
    const BatchHostMemory& memory = options.color_memory;
    uint8_t* destination =
        options.color_destination != nullptr ? options.color_destination : memory.Data();
    const size_t need = views * view_bytes;
    if (destination < memory.Data() || destination > memory.Data() + memory.Size() ||
        need > size_t(memory.Data() + memory.Size() - destination)) {
        core::ThrowError(
            "RenderBatch: {} views of {} bytes do not fit in the batch memory of {} bytes "
            "from offset {}",
            views, view_bytes, memory.Size(), static_cast<long long>(destination - memory.Data()));
    }
    return destination;
}

std::vector<RenderOutput> GaussianSplatBackend::RenderBatch(
    const std::vector<camera::PinholeCamera>& cameras, const RenderConfig& config,
    const BatchOptions& options) {
    CheckBatchCameras(cameras);
    CompositeInputs inputs;
    inputs.read_back = options.read_back;
    inputs.expected_depth = options.expected_depth;
    inputs.median_depth = options.median_depth;
    std::vector<RenderOutput> outputs;
    if (cameras.empty()) return outputs;
    outputs.reserve(cameras.size());
    uint8_t* const destination =
        options.read_back ? BatchColorDestination(options, cameras.size(),
                                                  size_t(cameras[0].width) * cameras[0].height * 4 *
                                                      (options.color_uint8 ? 1 : 4))
                          : nullptr;
    for (const camera::PinholeCamera& camera : cameras) {
        outputs.push_back(Render(camera, config, inputs));
        if (destination != nullptr) {
            RenderOutput& out = outputs.back();
            const t::geometry::Image color =
                options.color_uint8 ? ColorToUInt8(out.color) : std::move(out.color);
            const size_t bytes = static_cast<size_t>(color.AsTensor().NumBytes());
            std::memcpy(destination + (outputs.size() - 1) * bytes, color.AsTensor().RawData(),
                        bytes);
            out.color = t::geometry::Image();
            continue;
        }
        if (options.read_back && options.color_uint8) {
            outputs.back().color = ColorToUInt8(outputs.back().color);
        }
    }
    return outputs;
}

void RegisterGaussianSplatBackend(const std::string& name, GaussianSplatBackendFactory factory) {
    Registry& registry = GetRegistry();
    std::lock_guard<std::mutex> lock(registry.mutex);
    registry.factories[name] = std::move(factory);
}

std::vector<std::string> GetGaussianSplatBackendNames() {
    Registry& registry = GetRegistry();
    std::lock_guard<std::mutex> lock(registry.mutex);
    std::vector<std::string> names;
    for (const auto& kv : registry.factories) names.push_back(kv.first);
    return names;
}

std::unique_ptr<GaussianSplatBackend> CreateGaussianSplatBackend(const std::string& name) {
    GaussianSplatBackendFactory factory;
    {
        Registry& registry = GetRegistry();
        std::lock_guard<std::mutex> lock(registry.mutex);
        auto it = registry.factories.find(name);
        if (it != registry.factories.end()) factory = it->second;
    }
    if (!factory) {
        core::ThrowError("unknown Gaussian splat backend '{}' (known: {})", name,
                         fmt::join(GetGaussianSplatBackendNames(), ", "));
    }
    return factory();
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
