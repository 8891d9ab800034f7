// Levelled logging through fmt, with a replaceable sink so tests can count messages.
#pragma once

#include <fmt/format.h>

#include <functional>
#include <string>
#include <string_view>
#include <utility>

namespace open3d {
namespace core {

enum class LogLevel { Debug = 0, Info = 1, Warning = 2, Error = 3 };

using LogSink = std::function<void(LogLevel, std::string_view)>;

/// Messages below this level are dropped. Default: Info (env OPEN3D_LOG_LEVEL=debug lowers it).
void SetLogLevel(LogLevel level);
LogLevel GetLogLevel();

/// Replaces the sink (default: stderr with a level prefix). Returns the previous sink.
/// Pass nullptr to restore the default.
LogSink SetLogSink(LogSink sink);

void LogMessage(LogLevel level, std::string_view message);

/// While alive, every logged message has each `from` replaced by `to`: a writer that logs
/// the temporary file it writes to (t::io::OutputFileSet) then names the user's file.
/// ApplyLogAliases does the same to another text (an error's message).
std::string ApplyLogAliases(std::string_view message);

class ScopedLogAlias {
public:
    ScopedLogAlias(std::string from, std::string to);
    ~ScopedLogAlias();
    ScopedLogAlias(const ScopedLogAlias&) = delete;
    ScopedLogAlias& operator=(const ScopedLogAlias&) = delete;

private:
    size_t index_;
};

template <typename... Args>
void LogDebug(fmt::format_string<Args...> format, Args&&... args) {
    if (GetLogLevel() <= LogLevel::Debug)
        LogMessage(LogLevel::Debug, fmt::format(format, std::forward<Args>(args)...));
}
template <typename... Args>
void LogInfo(fmt::format_string<Args...> format, Args&&... args) {
    if (GetLogLevel() <= LogLevel::Info)
        LogMessage(LogLevel::Info, fmt::format(format, std::forward<Args>(args)...));
}
template <typename... Args>
void LogWarning(fmt::format_string<Args...> format, Args&&... args) {
    if (GetLogLevel() <= LogLevel::Warning)
        LogMessage(LogLevel::Warning, fmt::format(format, std::forward<Args>(args)...));
}
template <typename... Args>
void LogError(fmt::format_string<Args...> format, Args&&... args) {
    LogMessage(LogLevel::Error, fmt::format(format, std::forward<Args>(args)...));
}

}  // namespace core
}  // namespace open3d
