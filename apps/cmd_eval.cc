#include "apps/commands.h"
#include "core/util/error.h"

namespace pkslam::apps {

void RegisterEvalCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("eval", "(being implemented)");
  cmd->callback([] { throw Error("not implemented yet"); });
}

}  // namespace pkslam::apps
