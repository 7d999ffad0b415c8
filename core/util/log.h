// Levelled logging for the whole project (spdlog). Libraries log through these helpers so
// apps can route everything to the console and OUT/run.log with one call.
#pragma once

#include <filesystem>
#include <memory>
#include <string_view>

#include <spdlog/spdlog.h>

namespace pkslam {

// The project logger; created on first use with a console sink at level info.
std::shared_ptr<spdlog::logger> Logger();

// Route the project logger to the console and, additionally, to `file` (truncated).
void AddLogFile(const std::filesystem::path& file);
// Remove file sinks added by AddLogFile (flushes them).
void RemoveLogFiles();

// "trace", "debug", "info", "warn", "error", "off". Throws OptionError on an unknown name.
void SetLogLevel(std::string_view level);

}  // namespace pkslam

#define PKSLAM_LOG_DEBUG(...) ::pkslam::Logger()->debug(__VA_ARGS__)
#define PKSLAM_LOG_INFO(...) ::pkslam::Logger()->info(__VA_ARGS__)
#define PKSLAM_LOG_WARN(...) ::pkslam::Logger()->warn(__VA_ARGS__)
#define PKSLAM_LOG_ERROR(...) ::pkslam::Logger()->error(__VA_ARGS__)
