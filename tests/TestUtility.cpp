#include "TestUtility.h"

#include <cstdlib>
#include <filesystem>

namespace open3d {
namespace tests {

std::string DataDir() {
    if (const char* env = std::getenv("OPEN3D_DATA_DIR")) return env;
    return OPEN3D_DATA_DIR;
}

std::string DataPath(const std::string& relative) { return DataDir() + "/" + relative; }

bool FileExists(const std::string& path) { return std::filesystem::exists(path); }

bool SkipsAreFailures() {
    const char* ci = std::getenv("CI");
    return ci != nullptr && std::string(ci) == "true";
}

std::string TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "misc";
    for (char& c : name) {
        if (c == '/') c = '_';
    }
    const auto dir = std::filesystem::temp_directory_path() / "open3d_tests" / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir.string();
}

}  // namespace tests
}  // namespace open3d
