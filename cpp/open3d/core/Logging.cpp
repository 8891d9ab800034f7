#include "open3d/core/Logging.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

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
LogSink g_sink;                                              // empty = default stderr sink
std::vector<std::pair<std::string, std::string>> g_aliases;  // ScopedLogAlias, in order

std::string ApplyAliases(std::string_view message) {
    std::string text(message);
    for (const auto& [from, to] : g_aliases) {
        if (from.empty()) continue;
        for (size_t at = text.find(from); at != std::string::npos;
             at = text.find(from, at + to.size())) {
            text.replace(at, from.size(), to);
        }
    }
    return text;
}

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
    const std::string text = g_aliases.empty() ? std::string(message) : ApplyAliases(message);
    if (g_sink) {
        g_sink(level, text);
    } else {
        DefaultSink(level, text);
    }
}

std::string ApplyLogAliases(std::string_view message) {
    std::lock_guard<std::mutex> lock(g_sink_mutex);
    return ApplyAliases(message);
}

ScopedLogAlias::ScopedLogAlias(std::string from, std::string to) {
    std::lock_guard<std::mutex> lock(g_sink_mutex);
    index_ = g_aliases.size();
    g_aliases.emplace_back(std::move(from), std::move(to));
}

ScopedLogAlias::~ScopedLogAlias() {
    std::lock_guard<std::mutex> lock(g_sink_mutex);
    // Aliases end in reverse order of their start (scopes nest); an out-of-order end only
    // empties its own entry, and the list shrinks once the last entries are empty.
    g_aliases[index_].first.clear();
    while (!g_aliases.empty() && g_aliases.back().first.empty()) g_aliases.pop_back();
}

}  // namespace core
}  // namespace open3d
