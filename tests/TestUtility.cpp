#include "TestUtility.h"

#include "open3d/core/Logging.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

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

ScopedEnvironment::ScopedEnvironment(const std::string& name, const std::string& value)
    : name_(name) {
    if (const char* old = std::getenv(name.c_str())) {
        saved_ = old;
        was_set_ = true;
    }
    setenv(name.c_str(), value.c_str(), 1);
}

ScopedEnvironment::~ScopedEnvironment() {
    if (was_set_) {
        setenv(name_.c_str(), saved_.c_str(), 1);
    } else {
        unsetenv(name_.c_str());
    }
}

std::vector<uint8_t> ReadFileBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

void WriteFileBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

void AppendU32(std::vector<uint8_t>& bytes, uint32_t value) {
    for (int i = 0; i < 4; ++i) bytes.push_back(uint8_t(value >> (8 * i)));
}

void AppendU64(std::vector<uint8_t>& bytes, uint64_t value) {
    AppendU32(bytes, uint32_t(value));
    AppendU32(bytes, uint32_t(value >> 32));
}

std::vector<std::string> CaptureWarnings(const std::function<void()>& call) {
    std::vector<std::string> warnings;
    core::LogSink previous =
        core::SetLogSink([&warnings](core::LogLevel level, std::string_view message) {
            if (level == core::LogLevel::Warning) warnings.emplace_back(message);
        });
    try {
        call();
    } catch (...) {
        core::SetLogSink(previous);
        throw;
    }
    core::SetLogSink(previous);
    return warnings;
}

}  // namespace tests
}  // namespace open3d
