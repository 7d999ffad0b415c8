#include "apps/cli_outputs.h"

#include <filesystem>
#include <string>
#include <vector>

#include "apps/cli_errors.h"
#include "core/util/output_guard.h"

namespace pkslam::apps {
namespace {

// Options that name data a command reads and must leave alone. --run is not among them: a run
// folder is pkslam's own output, and `dense` or `view` write beside its files on purpose.
const std::vector<std::string> kFolderInputFlags = {"--dataset", "--images", "DATASET"};
// Inputs that are files: an output may sit beside them, only not on them (a folder given there
// by mistake is the command's own error to name).
const std::vector<std::string> kFileInputFlags = {"--video", "--settings", "--timestamps", "--gt",
                                                  "--est",   "--load-map", "--vocabulary", "FILE"};
const std::vector<std::string> kOutputFlags = {"--out", "--save-map", "--json"};

}  // namespace

void CheckOutputsAgainstInputs(CLI::App& app) {
  CLI::App* command = DeepestSubcommand(app);
  const auto values = [command](const std::string& flag) {
    std::vector<std::string> out;
    const CLI::Option* option = nullptr;
    try {
      option = command->get_option(flag);
    } catch (const CLI::OptionNotFound&) {
      return out;
    }
    if (option->count() == 0) return out;
    for (const std::string& v : option->results()) out.push_back(v);
    return out;
  };
  for (const std::string& out_flag : kOutputFlags) {
    for (const std::string& output : values(out_flag)) {
      for (const std::string& in_flag : kFolderInputFlags) {
        for (const std::string& input : values(in_flag)) {
          CheckOutputIsNotInput(output, out_flag, input, in_flag);
        }
      }
      for (const std::string& in_flag : kFileInputFlags) {
        for (const std::string& input : values(in_flag)) {
          if (std::filesystem::is_directory(input)) continue;
          CheckOutputIsNotInput(output, out_flag, input, in_flag);
        }
      }
    }
  }
}

}  // namespace pkslam::apps
