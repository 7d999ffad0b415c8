#include "apps/cli_errors.h"

#include <fmt/format.h>

#include <iostream>

#include "core/sensor/sensor.h"
#include "core/util/closest_match.h"

namespace pkslam::apps {
namespace {

// Every flag spelling ("--sensor", "-h") of `command` and the commands above it (a global flag
// such as --log-level is valid anywhere).
std::vector<std::string> FlagNames(const CLI::App* command) {
  std::vector<std::string> names;
  for (const CLI::App* c = command; c != nullptr; c = c->get_parent()) {
    for (const CLI::Option* option : c->get_options()) {
      for (const std::string& n : option->get_lnames()) names.push_back("--" + n);
      for (const std::string& n : option->get_snames()) names.push_back("-" + n);
    }
  }
  return names;
}

std::vector<std::string> SubcommandNames(const CLI::App* command) {
  std::vector<std::string> names;
  for (const CLI::App* sub : command->get_subcommands({})) names.push_back(sub->get_name());
  return names;
}

std::string CommandPath(const CLI::App* command) {
  std::string path;
  for (const CLI::App* c = command; c->get_parent() != nullptr; c = c->get_parent()) {
    path = c->get_name() + (path.empty() ? "" : " " + path);
  }
  return path;
}

// For "arguments were not expected": the first unknown flag or word with its nearest valid one.
std::string UnexpectedHint(CLI::App* command, int argc, char** argv) {
  const std::vector<std::string> flags = FlagNames(command);
  const std::vector<std::string> subcommands = SubcommandNames(command);
  for (int i = 1; i < argc; ++i) {
    std::string word = argv[i];
    if (word.rfind("--", 0) == 0) {
      word = word.substr(0, word.find('='));
      if (std::find(flags.begin(), flags.end(), word) != flags.end()) continue;
      const std::string hint = DidYouMean(word, flags);
      if (!hint.empty()) return fmt::format("unknown flag '{}'{}", word, hint);
    } else if (!subcommands.empty() && word.rfind('-', 0) != 0) {
      if (std::find(subcommands.begin(), subcommands.end(), word) != subcommands.end()) continue;
      const std::string hint = DidYouMean(word, subcommands);
      if (!hint.empty()) return fmt::format("unknown command '{}'{}", word, hint);
    }
  }
  return "";
}

}  // namespace

CLI::App* DeepestSubcommand(CLI::App& app) {
  CLI::App* current = &app;
  while (!current->get_subcommands().empty()) current = current->get_subcommands().back();
  return current;
}

std::vector<std::string> SensorNames() {
  std::vector<std::string> names;
  for (const Sensor s : {Sensor::kMonocular, Sensor::kStereo, Sensor::kRgbd,
                         Sensor::kMonocularInertial, Sensor::kStereoInertial,
                         Sensor::kRgbdInertial}) {
    names.emplace_back(SensorName(s));
  }
  return names;
}

int ReportParseError(CLI::App& app, const CLI::ParseError& error, int argc, char** argv) {
  if (error.get_exit_code() == 0) return app.exit(error);  // --help, --version
  CLI::App* command = DeepestSubcommand(app);
  std::string message = error.what();
  // A mistyped word often shows first as another error ("--gt is required" for --gtt).
  const std::string hint = UnexpectedHint(command, argc, argv);
  if (dynamic_cast<const CLI::RequiredError*>(&error) != nullptr && command == &app) {
    message = hint.empty() ? fmt::format("a command is required: {}",
                                         fmt::join(SubcommandNames(&app), ", "))
                           : hint;
  } else if (!hint.empty()) {
    message += "; " + hint;
  }
  const std::string path = CommandPath(command);
  std::cerr << "pkslam: error: " << message << " (see pkslam " << (path.empty() ? "" : path + " ")
            << "--help)\n";
  return 1;
}

CLI::Validator OneOf(std::vector<std::string> values, std::string why) {
  const std::string description = fmt::format("{{{}}}", fmt::join(values, ", "));
  return CLI::Validator(
      [values, why](std::string& value) -> std::string {
        if (std::find(values.begin(), values.end(), value) != values.end()) return "";
        return fmt::format("'{}' is not one of {}{}{}", value, fmt::join(values, ", "),
                           why.empty() ? "" : ": " + why, DidYouMean(value, values));
      },
      description);
}

}  // namespace pkslam::apps
