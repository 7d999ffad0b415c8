// pkslam info DATASET [--json OUT]: what a dataset holds and what is wrong with it.
#include <fstream>
#include <iostream>
#include <memory>
#include <string>

#include "apps/commands.h"
#include "core/util/error.h"
#include "core/util/output_file.h"
#include "io/dataset_info.h"

namespace pkslam::apps {

namespace {

struct InfoArgs {
  std::string dataset;
  std::string json_out;
};

void RunInfo(const InfoArgs& args) {
  const DatasetInfo info = ComputeDatasetInfo(args.dataset);
  std::cout << FormatDatasetInfo(info) << std::flush;
  if (!args.json_out.empty()) {
    WriteFileAtomically(args.json_out, DatasetInfoToJson(info));
  }
}

}  // namespace

void RegisterInfoCommand(CLI::App& app) {
  auto args = std::make_shared<InfoArgs>();
  auto* cmd = app.add_subcommand(
      "info",
      "Summarise a dataset (EuRoC ASL or TUM RGB-D, auto-detected): sensors, resolutions, "
      "nominal and measured rates, time spans, frame / stereo pair / rgb-depth pair / IMU / "
      "ground-truth counts, frame and IMU gaps, missing image files");
  cmd->add_option("DATASET", args->dataset,
                  "dataset directory (EuRoC: the sequence dir holding mav0/; TUM: the dir "
                  "holding rgb.txt)")
      ->required();
  cmd->add_option("--json", args->json_out, "also write the summary as JSON to this file");
  cmd->footer("Example: pkslam info ../shared/data/euroc/V1_01_easy_static --json info.json");
  cmd->callback([args] { RunInfo(*args); });
}

}  // namespace pkslam::apps
