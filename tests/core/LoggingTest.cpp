#include "open3d/core/Logging.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace open3d {
namespace core {

TEST(Logging, SinkReceivesFormattedMessagesAboveLevel) {
    std::vector<std::pair<LogLevel, std::string>> seen;
    LogSink previous = SetLogSink(
        [&](LogLevel level, std::string_view msg) { seen.emplace_back(level, std::string(msg)); });
    const LogLevel old_level = GetLogLevel();
    SetLogLevel(LogLevel::Warning);
    LogInfo("hidden {}", 1);
    LogWarning("shown {}", 2);
    SetLogLevel(old_level);
    SetLogSink(previous);
    ASSERT_EQ(seen.size(), 1u);
    EXPECT_EQ(seen[0].first, LogLevel::Warning);
    EXPECT_EQ(seen[0].second, "shown 2");
}

}  // namespace core
}  // namespace open3d
