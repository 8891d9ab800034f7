// Helpers of the t/io tests: reading a file into a cloud, a float attribute's data, and the
// check of a refused file (ReadPointCloud throws core::Open3DError whose message names the
// file and holds every fragment, and the output cloud is left as it was).
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/Tensor.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {

/// The cloud in `path` (throws as ReadPointCloud does).
inline geometry::PointCloud ReadCloud(const std::string& path) {
    geometry::PointCloud cloud;
    ReadPointCloud(path, cloud);
    return cloud;
}

/// The float data of attribute `name`.
inline const float* FloatsOf(const geometry::PointCloud& cloud, const char* name) {
    return cloud.GetPointAttr(name).Data<float>();
}

inline void ExpectReadError(const std::string& path, const std::vector<std::string>& fragments,
                            const ReadPointCloudOptions& options = {}) {
    geometry::PointCloud cloud(core::Tensor::FromVector<float>({7, 8, 9}, {1, 3}));
    const geometry::PointCloud before = cloud;
    try {
        ReadPointCloud(path, cloud, options);
        ADD_FAILURE() << "no error reading " << path;
    } catch (const core::Open3DError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(path), std::string::npos) << message;
        for (const auto& fragment : fragments) {
            EXPECT_NE(message.find(fragment), std::string::npos)
                << "'" << fragment << "' not in: " << message;
        }
    }
    EXPECT_TRUE(cloud == before) << "a failed read changed the output cloud";
}

}  // namespace io
}  // namespace t
}  // namespace open3d
