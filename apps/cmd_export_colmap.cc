// pkslam export-colmap: a run's keyframes, keypoints and map points as a COLMAP text model
// with the rectified/undistorted keyframe images (see dense/colmap_export.h).
#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "apps/commands.h"
#include "core/util/error.h"
#include "dense/colmap_export.h"
#include "io/dataset_fingerprint.h"
#include "io/sparse_model.h"

namespace pkslam::apps {
namespace {

namespace fs = std::filesystem;

struct ExportArgs {
  std::string run;
  std::string dataset;
  std::string settings;
  std::string out;
  bool no_images = false;
  dense::ColmapExportOptions options;
};

void RunExport(ExportArgs args) {
  args.options.write_images = !args.no_images;
  args.options.Check();
  if (!fs::is_directory(args.run)) throw InputError(args.run, "run directory does not exist");
  const fs::path model_file = fs::path(args.run) / "sparse_model.txt";
  if (!fs::exists(model_file)) {
    throw InputError(model_file, "no sparse_model.txt (made by `pkslam run` of this version)");
  }
  const SparseModel model = ReadSparseModel(model_file);
  if (model.keyframes.empty()) throw InputError(model_file, "the sparse model has no keyframes");
  const auto source = dense::KeyframeImageSource::Open(
      args.dataset, args.settings.empty() ? std::nullopt : std::optional<fs::path>(args.settings));
  RequireRunOfDataset(args.run, args.dataset);
  const dense::ColmapExportStats s = dense::ExportColmap(model, source, args.options, args.out);
  fmt::print("images {}, points {} ({} with shorter tracks left out), observations {}\n", s.images,
             s.points, s.points_dropped, s.observations);
  fmt::print("mean track length {:.2f}, mean reprojection error {:.3f} px\n", s.mean_track_length,
             s.mean_reprojection_error_px);
  fmt::print("model: {}/sparse/{{cameras,images,points3D}}.txt, images: {}/images/\n", args.out,
             args.out);
}

}  // namespace

void RegisterExportColmapCommand(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  auto* cmd = app.add_subcommand(
      "export-colmap",
      "Write a run's keyframes as a COLMAP text model (PINHOLE camera, keyframe poses and "
      "keypoints, map points with tracks) plus the rectified/undistorted keyframe images");
  cmd->add_option("--run", args->run, "Run directory of `pkslam run` (sparse_model.txt)")
      ->required();
  cmd->add_option("--dataset", args->dataset, "The dataset the run used")->required();
  cmd->add_option("--out", args->out, "Output directory (images/ and sparse/)")->required();
  cmd->add_option("--settings", args->settings, "The settings file the run used (if any)");
  cmd->add_option("--min-track-length", args->options.min_track_length,
                  "Leave out map points seen by fewer keyframes")
      ->capture_default_str();
  cmd->add_flag("--no-images", args->no_images, "Write only the text model");
  cmd->add_flag("--quiet", args->options.quiet, "No progress bar");
  cmd->callback([args] { RunExport(*args); });
}

}  // namespace pkslam::apps
