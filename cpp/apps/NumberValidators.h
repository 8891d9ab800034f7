// CLI11 validators of the apps' numeric flags, stated in words and refusing non-finite
// values: CLI::PositiveNumber printed "[2.22507e-308 - 1.79769e+308]" with every digit of
// the double limits, and it and NonNegativeNumber accept "inf" (and CLI11 parses "nan").
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdlib>
#include <string>

namespace open3d {
namespace apps {

/// A number (the whole text) that `accept` takes; else "'TEXT' REQUIREMENT", which CLI11
/// prints after the flag's name ("--spin: 'inf' must be a finite number").
inline CLI::Validator NumberCheck(bool (*accept)(double), const std::string& requirement,
                                  const std::string& help) {
    return CLI::Validator(
        [accept, requirement](std::string& text) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(text.c_str(), &end);
            if (text.empty() || *end != '\0' || !accept(v)) {
                return "'" + text + "' " + requirement;
            }
            return "";
        },
        help);
}

inline const CLI::Validator kPositive = NumberCheck(
    [](double v) { return v > 0.0 && std::isfinite(v); }, "must be finite and > 0", "POSITIVE");
inline const CLI::Validator kNonNegative =
    NumberCheck([](double v) { return v >= 0.0 && std::isfinite(v); }, "must be finite and >= 0",
                "NON-NEGATIVE");
inline const CLI::Validator kFinite =
    NumberCheck([](double v) { return std::isfinite(v); }, "must be a finite number", "FINITE");
inline const CLI::Validator kUnit =
    NumberCheck([](double v) { return v >= 0.0 && v <= 1.0; }, "must be in 0..1", "0..1");

}  // namespace apps
}  // namespace open3d
