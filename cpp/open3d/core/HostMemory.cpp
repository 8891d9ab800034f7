#include "open3d/core/HostMemory.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "open3d/core/Exception.h"

namespace open3d {
namespace core {

namespace {

constexpr uint64_t kUnknown = std::numeric_limits<uint64_t>::max();

// These reads use C stdio, not iostreams: in a Python process that had loaded NumPy 2's wheels
// before this module, std::ifstream extraction here read "max" from memory.max as something
// else, which became a limit of 0 bytes and refused every load (docs/environment-notes.md).

// The first line of a small file, without its newline; false when it cannot be read.
bool ReadFirstLine(const std::string& path, std::string& line) {
    FILE* file = std::fopen(path.c_str(), "r");
    if (file == nullptr) return false;
    char buffer[4096];
    const bool ok = std::fgets(buffer, sizeof(buffer), file) != nullptr;
    std::fclose(file);
    if (!ok) return false;
    line = buffer;
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    return true;
}

// A whole line that is a decimal count; false for anything else ("max", empty, garbage).
bool ParseCount(const std::string& text, uint64_t& value) {
    if (text.empty() || text[0] < '0' || text[0] > '9') return false;
    char* end = nullptr;
    errno = 0;
    const unsigned long long parsed = std::strtoull(text.c_str(), &end, 10);
    if (errno != 0 || end == nullptr || *end != '\0') return false;
    value = parsed;
    return true;
}

// "MemAvailable:   23456789 kB" -> bytes.
uint64_t ReadMemAvailable() {
    FILE* file = std::fopen("/proc/meminfo", "r");
    if (file == nullptr) return kUnknown;
    char line[256];
    uint64_t bytes = kUnknown;
    while (std::fgets(line, sizeof(line), file) != nullptr) {
        unsigned long long kb = 0;
        if (std::sscanf(line, "MemAvailable: %llu kB", &kb) == 1) {
            bytes = uint64_t(kb) * 1024;
            break;
        }
    }
    std::fclose(file);
    return bytes;
}

// The room the process's memory cgroup leaves: cgroup v2 memory.max - memory.current, or
// v1 memory.limit_in_bytes - memory.usage_in_bytes ("max" or a huge v1 value: no limit). A
// file that does not hold a count says nothing (no limit from it), never a limit of 0.
uint64_t ReadCgroupRoom() {
    FILE* cgroup = std::fopen("/proc/self/cgroup", "r");
    if (cgroup == nullptr) return kUnknown;
    std::vector<std::string> lines;
    char buffer[4096];
    while (std::fgets(buffer, sizeof(buffer), cgroup) != nullptr) {
        std::string line = buffer;
        while (!line.empty() && line.back() == '\n') line.pop_back();
        lines.push_back(line);
    }
    std::fclose(cgroup);
    for (const std::string& line : lines) {
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
        std::string limit_text, usage_text;
        uint64_t limit = 0, usage = 0;
        if (!ReadFirstLine(limit_path, limit_text) || !ParseCount(limit_text, limit) ||
            !ReadFirstLine(usage_path, usage_text) || !ParseCount(usage_text, usage)) {
            continue;
        }
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
