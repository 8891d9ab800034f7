#include "open3d/core/HostMemory.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <string>

#include "open3d/core/Exception.h"

namespace open3d {
namespace core {

namespace {

constexpr uint64_t kUnknown = std::numeric_limits<uint64_t>::max();

// "MemAvailable:   23456789 kB" -> bytes.
uint64_t ReadMemAvailable() {
    std::ifstream in("/proc/meminfo");
    std::string key;
    uint64_t kb = 0;
    std::string unit;
    while (in >> key >> kb >> unit) {
        if (key == "MemAvailable:") return kb * 1024;
    }
    return kUnknown;
}

// The room the process's memory cgroup leaves: cgroup v2 memory.max - memory.current, or
// v1 memory.limit_in_bytes - memory.usage_in_bytes ("max" or a huge v1 value: no limit).
uint64_t ReadCgroupRoom() {
    std::ifstream cgroup("/proc/self/cgroup");
    std::string line;
    while (std::getline(cgroup, line)) {
        std::string limit_path, usage_path;
        if (line.rfind("0::", 0) == 0) {
            const std::string dir = "/sys/fs/cgroup" + line.substr(3);
            limit_path = dir + "/memory.max";
            usage_path = dir + "/memory.current";
        } else if (const size_t at = line.find(":memory:"); at != std::string::npos) {
            const std::string dir = "/sys/fs/cgroup/memory" + line.substr(at + 8);
            limit_path = dir + "/memory.limit_in_bytes";
            usage_path = dir + "/memory.usage_in_bytes";
        } else {
            continue;
        }
        std::ifstream limit_file(limit_path), usage_file(usage_path);
        std::string limit_text;
        uint64_t usage = 0;
        if (!(limit_file >> limit_text) || limit_text == "max" || !(usage_file >> usage)) continue;
        const uint64_t limit = std::strtoull(limit_text.c_str(), nullptr, 10);
        if (limit >= (uint64_t(1) << 60)) continue;  // v1 writes "no limit" as ~2^63
        return limit > usage ? limit - usage : 0;
    }
    return kUnknown;
}

uint64_t ReadLimitVariable() {
    return ReadByteCountVariable("OPEN3D_HOST_MEMORY_LIMIT").value_or(kUnknown);
}

}  // namespace

std::optional<uint64_t> ReadByteCountVariable(const char* name) {
    const char* text = std::getenv(name);
    if (text == nullptr || text[0] == '\0') return std::nullopt;
    return ParseByteCount(text, name);
}

uint64_t ParseByteCount(const std::string& text, const std::string& what) {
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    const std::string suffix = end ? std::string(end) : "";
    double unit = -1.0;
    if (suffix.empty()) unit = 1.0;
    if (suffix == "K" || suffix == "k") unit = 1024.0;
    if (suffix == "M") unit = 1024.0 * 1024.0;
    if (suffix == "G") unit = 1024.0 * 1024.0 * 1024.0;
    if (suffix == "T") unit = 1024.0 * 1024.0 * 1024.0 * 1024.0;
    if (text.empty() || end == text.c_str() || unit < 0 || !(value * unit >= 1.0) ||
        !std::isfinite(value * unit) || value * unit > 1.8e19) {
        ThrowError("{}: '{}' is not a size in bytes (for example 2G, 512M, 1.5G, 123456)", what,
                   text);
    }
    return static_cast<uint64_t>(value * unit);
}

uint64_t AvailableHostMemory() {
    return std::min({ReadMemAvailable(), ReadCgroupRoom(), ReadLimitVariable()});
}

std::string FormatBytes(uint64_t bytes) {
    if (bytes >= 1000000000ull) return fmt::format("{:.2f} GB", bytes / 1e9);
    if (bytes >= 1000000ull) return fmt::format("{:.1f} MB", bytes / 1e6);
    if (bytes >= 1000ull) return fmt::format("{:.1f} kB", bytes / 1e3);
    return fmt::format("{} bytes", bytes);
}

void RequireHostMemory(uint64_t bytes, const std::string& what, const std::string& hint) {
    const uint64_t available = AvailableHostMemory();
    if (bytes <= available) return;
    const bool capped = ReadByteCountVariable("OPEN3D_HOST_MEMORY_LIMIT") == available;
    ThrowError("{} needs {} of memory, {} is available ({}){}{}", what, FormatBytes(bytes),
               FormatBytes(available),
               capped ? "OPEN3D_HOST_MEMORY_LIMIT" : "MemAvailable and the cgroup limit",
               hint.empty() ? "" : "; ", hint);
}

}  // namespace core
}  // namespace open3d
