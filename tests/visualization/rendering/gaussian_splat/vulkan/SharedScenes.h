// The shared scenes the Vulkan backend's whole-frame tests render at CI sizes (playbot_31k,
// chair, biker_152k from ../shared/data) and the two views of each they take.
#pragma once

#include <string>
#include <tuple>
#include <vector>

#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace tests {

struct SharedSceneFiles {
    const char* scene;
    const char* cameras;
};

inline constexpr SharedSceneFiles kSharedScenes[] = {
    {"playbot/playbot_31k.ply", "playbot/cameras.json"},
    {"chair/chair.splat", "chair/cameras.json"},
    {"biker/biker_152k.ply", "biker/cameras.json"}};

/// (view index, width, height): a square view and an off-aspect one.
inline constexpr std::tuple<int, int, int> kSharedSceneViews[] = {{0, 96, 96}, {5, 100, 75}};

struct SharedScene {
    t::geometry::PointCloud cloud;
    std::vector<camera::CameraView> views;
};

/// Reads a scene and its cameras (the caller checks OPEN3D_REQUIRE_DATA first, to skip or fail).
inline SharedScene ReadSharedScene(const SharedSceneFiles& files) {
    SharedScene s;
    t::io::ReadPointCloud(DataPath(files.scene), s.cloud);
    s.views = camera::ReadCamerasJson(DataPath(files.cameras));
    return s;
}

}  // namespace tests
}  // namespace open3d
