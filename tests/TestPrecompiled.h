// The precompiled header of every test binary (tests/CMakeLists.txt): what most tests include,
// parsed once per build instead of once per test file. Only headers of the lowest layers
// (core, geometry, io, camera) and third-party headers, so that every test binary can use it.
// Tests still include what they use; this file only makes it cheaper.
#pragma once

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/io/PointCloudIO.h"
