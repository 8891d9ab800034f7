#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"

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

RenderOutput GaussianSplatBackend::Render(const camera::PinholeCamera& camera,
                                          const RenderConfig& config) {
    RenderGeometryStage(camera, config);
    RenderOutput output;
    RenderCompositeStage(output);
    return output;
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
