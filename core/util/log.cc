#include "core/util/log.h"

#include <mutex>

#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>

#include "core/util/error.h"

namespace pkslam {
namespace {

constexpr const char* kLoggerName = "pkslam";

// The logger lives in spdlog's process-wide registry (logging is process-wide by nature);
// this mutex serialises its creation and every change to its sink list.
std::mutex logger_mutex;

std::shared_ptr<spdlog::logger> CreateLoggerLocked() {
  auto console = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  auto logger = std::make_shared<spdlog::logger>(kLoggerName, console);
  logger->set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");
  logger->set_level(spdlog::level::info);
  spdlog::register_logger(logger);
  return logger;
}

}  // namespace

std::shared_ptr<spdlog::logger> Logger() {
  if (auto logger = spdlog::get(kLoggerName)) return logger;
  std::lock_guard lock(logger_mutex);
  if (auto logger = spdlog::get(kLoggerName)) return logger;
  return CreateLoggerLocked();
}

void AddLogFile(const std::filesystem::path& file) {
  auto logger = Logger();
  std::lock_guard lock(logger_mutex);
  auto sink = std::make_shared<spdlog::sinks::basic_file_sink_mt>(file.string(), true);
  sink->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%l] [t%t] %v");
  sink->set_level(spdlog::level::trace);
  logger->sinks().push_back(sink);
}

void RemoveLogFiles() {
  auto logger = Logger();
  std::lock_guard lock(logger_mutex);
  auto& sinks = logger->sinks();
  for (auto& s : sinks) s->flush();
  std::erase_if(sinks, [](const spdlog::sink_ptr& s) {
    return std::dynamic_pointer_cast<spdlog::sinks::basic_file_sink_mt>(s) != nullptr;
  });
}

void SetLogLevel(std::string_view level) {
  const auto parsed = spdlog::level::from_str(std::string(level));
  if (parsed == spdlog::level::off && level != "off") {
    throw OptionError(fmt::format("unknown log level '{}'", level));
  }
  Logger()->set_level(parsed);
}

}  // namespace pkslam
