#include "open3d/core/Logging.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace open3d {
namespace core {
namespace {

LogLevel InitialLevel() {
    const char* env = std::getenv("OPEN3D_LOG_LEVEL");
    if (env == nullptr) return LogLevel::Info;
    if (std::strcmp(env, "debug") == 0) return LogLevel::Debug;
    if (std::strcmp(env, "warning") == 0) return LogLevel::Warning;
    if (std::strcmp(env, "error") == 0) return LogLevel::Error;
    return LogLevel::Info;
}

std::atomic<LogLevel> g_level{InitialLevel()};
std::mutex g_sink_mutex;
LogSink g_sink;  // empty = default stderr sink

void DefaultSink(LogLevel level, std::string_view message) {
    static const char* kPrefix[] = {"[debug] ", "", "[warning] ", "[error] "};
    std::fprintf(stderr, "%s%.*s\n", kPrefix[static_cast<int>(level)],
                 static_cast<int>(message.size()), message.data());
}

}  // namespace

void SetLogLevel(LogLevel level) { g_level = level; }
LogLevel GetLogLevel() { return g_level; }

LogSink SetLogSink(LogSink sink) {
    std::lock_guard<std::mutex> lock(g_sink_mutex);
    LogSink previous = std::move(g_sink);
    g_sink = std::move(sink);
    return previous;
}

void LogMessage(LogLevel level, std::string_view message) {
    std::lock_guard<std::mutex> lock(g_sink_mutex);
    if (g_sink) {
        g_sink(level, message);
    } else {
        DefaultSink(level, message);
    }
}

}  // namespace core
}  // namespace open3d
