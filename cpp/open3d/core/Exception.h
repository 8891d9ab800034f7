// One exception type for failures a user can act on: bad files, bad arguments,
// missing devices. Invariants use assertions; GPU runtime conditions use flag words.
#pragma once

#include <fmt/format.h>

#include <stdexcept>
#include <string>

namespace open3d {
namespace core {

class Open3DError : public std::runtime_error {
public:
    explicit Open3DError(const std::string& message) : std::runtime_error(message) {}
};

/// Throws Open3DError with a fmt-formatted message.
template <typename... Args>
[[noreturn]] void ThrowError(fmt::format_string<Args...> format, Args&&... args) {
    throw Open3DError(fmt::format(format, std::forward<Args>(args)...));
}

}  // namespace core
}  // namespace open3d
