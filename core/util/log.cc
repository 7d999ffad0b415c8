#include "core/util/log.h"

#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>

#include <cstdio>
#include <mutex>

#include "core/util/error.h"

namespace pkslam {
namespace {

constexpr const char* kLoggerName = "pkslam";

// The logger lives in spdlog's process-wide registry (logging is process-wide by nature);
// this mutex serialises its creation and every change to its sink list.
std::mutex logger_mutex;
// A log file that cannot be written is reported once per process.
std::once_flag log_error_reported;

std::shared_ptr<spdlog::logger> CreateLoggerLocked() {
  auto console = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  auto logger = std::make_shared<spdlog::logger>(kLoggerName, console);
  logger->set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");
  logger->set_level(spdlog::level::info);
  // Logging never stops a run: a log file that cannot be written (full disk) is reported once
  // on stderr instead of spdlog's rate-limited notes, and the run goes on to fail, if at all,
  // on its real outputs with an error naming the file.
  logger->set_error_handler([](const std::string& message) {
    std::call_once(log_error_reported, [&] {
      std::fprintf(stderr,
                   "pkslam: warning: the log file cannot be written (%s); logging to "
                   "stderr only\n",
                   message.c_str());
    });
  });
  // Flushed at every info message, so that a killed run (SIGKILL) leaves its log.
  logger->flush_on(spdlog::level::info);
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
  std::shared_ptr<spdlog::sinks::basic_file_sink_mt> sink;
  try {
    sink = std::make_shared<spdlog::sinks::basic_file_sink_mt>(file.string(), true);
  } catch (const spdlog::spdlog_ex& e) {
    throw OutputError(file, e.what());
  }
  sink->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%l] [t%t] %v");
  sink->set_level(spdlog::level::trace);
  logger->sinks().push_back(sink);
}

void RemoveLogFiles() {
  auto logger = Logger();
  std::lock_guard lock(logger_mutex);
  auto& sinks = logger->sinks();
  // Called from destructors: a failing flush (full disk) must not throw out of them.
  for (auto& s : sinks) {
    try {
      s->flush();
    } catch (const spdlog::spdlog_ex& e) {
      std::fprintf(stderr, "pkslam: warning: the log file cannot be flushed (%s)\n", e.what());
    }
  }
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
