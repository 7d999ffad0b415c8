// pkslam cloud-compare: accuracy and completeness of a cloud against a reference cloud
// (see dense/cloud_compare.h), optionally after aligning a SLAM cloud to the reference frame
// through the run's trajectory and ground truth, and with completeness restricted to the
// reference points the run's keyframes saw (dense/visibility.h).
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "core/util/error.h"
#include "core/util/json_writer.h"
#include "core/util/output_file.h"
#include "dense/cloud_compare.h"
#include "dense/histogram_plot.h"
#include "dense/keyframe_images.h"
#include "dense/mesh.h"
#include "dense/visibility.h"
#include "evaluation/evaluate.h"
#include "io/point_cloud.h"
#include "io/rigid_transform_file.h"
#include "io/trajectory.h"

namespace pkslam::apps {
namespace {

namespace fs = std::filesystem;

struct CompareArgs {
  std::string cloud;
  std::string ref;
  std::string hist;
  std::string json;
  std::string align_run;
  std::string gt;
  std::string align = "se3";
  std::string dataset;
  std::string settings;
  std::string write_aligned;
  std::vector<std::string> observed_refs;
  double max_diff_s = 0.01;
  double mesh_spacing_m = 0.005;
  dense::CompareOptions compare;
  dense::VisibilityOptions visibility;
};

struct Alignment {
  Sim3d ref_from_slam;
  EvaluationResult evaluation;
  fs::path estimate;
};

Alignment AlignRun(const CompareArgs& args) {
  const fs::path run = args.align_run;
  if (!fs::is_directory(run)) throw InputError(run, "run directory does not exist");
  if (args.gt.empty()) throw OptionError("--align-run needs --gt (the ground-truth trajectory)");
  // Body poses against EuRoC ground truth; monocular runs (no trajectory_body.txt) on camera
  // poses against the ground truth moved into the camera.
  const RunAndGroundTruth pair = ReadRunAndGroundTruth(run, args.gt, std::nullopt);
  const Trajectory& gt = pair.ground_truth;
  const Trajectory& est = pair.estimate;
  const fs::path estimate = pair.estimate_file;
  EvaluationOptions options;
  options.alignment = ParseAlignmentMethod(args.align);
  if (options.alignment != AlignmentMethod::kSE3 && options.alignment != AlignmentMethod::kSim3) {
    throw OptionError("--align must be se3 or sim3");
  }
  options.association.max_diff_s = args.max_diff_s;
  options.compute_rpe = false;
  Alignment a;
  a.evaluation = EvaluateTrajectories(gt, est, options);
  a.ref_from_slam = a.evaluation.ref_from_est;
  a.estimate = estimate;
  return a;
}

void PrintStats(const char* name, const dense::DistanceStats& s) {
  fmt::print("{:<13} n {:>9}  mean {:.4f}  median {:.4f}  rms {:.4f}  max {:.3f} m", name, s.count,
             s.mean, s.median, s.rms, s.max);
  for (std::size_t t = 0; t < s.thresholds_m.size(); ++t) {
    fmt::print("  <={:g}cm {:.1f}%", s.thresholds_m[t] * 100, 100 * s.within[t]);
  }
  fmt::print("\n");
}

// The cloud to measure: a PLY's points, or points sampled on a mesh's triangles (a PLY with
// faces, e.g. `pkslam dense --mesh`).
PointCloud ReadCloud(const CompareArgs& args) {
  if (!dense::PlyHasFaces(args.cloud)) return ReadPly(args.cloud);
  PointCloud cloud = dense::SampleMesh(args.cloud, args.mesh_spacing_m);
  fmt::print("mesh: {} points sampled on its triangles ({} m spacing)\n", cloud.size(),
             args.mesh_spacing_m);
  return cloud;
}

// --align-run: moves the cloud into the reference's frame by the run's trajectory alignment.
std::optional<Alignment> AlignCloud(const CompareArgs& args, PointCloud* cloud) {
  if (args.align_run.empty()) return std::nullopt;
  Alignment alignment = AlignRun(args);
  for (auto& p : cloud->points) {
    p = (alignment.ref_from_slam * p.cast<double>()).cast<float>();
  }
  fmt::print("aligned by {} ({} pose pairs of {}): trajectory ATE rmse {:.4f} m, scale {:.4f}\n",
             args.align, alignment.evaluation.pairs.size(), alignment.estimate.string(),
             alignment.evaluation.ate_translation_m.rmse, alignment.ref_from_slam.scale());
  if (!args.write_aligned.empty()) {
    WritePly(*cloud, args.write_aligned, cloud->has_colour() ? PlyColour::kRgb : PlyColour::kNone,
             "pkslam cloud-compare: cloud aligned to the reference frame");
  }
  return alignment;
}

// --dataset: which reference points the run's keyframes saw (empty without it).
std::vector<std::uint8_t> VisibleReferencePoints(const CompareArgs& args,
                                                 const Alignment& alignment,
                                                 const PointCloud& ref) {
  const fs::path keyframes_file = fs::path(args.align_run) / "keyframes.txt";
  const Trajectory keyframes = ReadTrajectory(keyframes_file, TrajectoryFormat::kTum);
  const auto source = dense::KeyframeImageSource::Open(
      args.dataset, args.settings.empty() ? std::nullopt : std::optional<fs::path>(args.settings));
  std::vector<SE3d> camera_from_ref;
  const Sim3d& s = alignment.ref_from_slam;
  for (const StampedPose& kf : keyframes.poses) {
    const SE3d ref_from_camera(s.so3() * kf.pose.so3(), s * kf.pose.translation());
    camera_from_ref.push_back(ref_from_camera.Inverse());
  }
  return dense::VisibleFromCameras(ref.points, camera_from_ref, source.camera(), args.visibility);
}

void PrintComparison(const CompareArgs& args, const dense::CompareResult& r, bool aligned) {
  fmt::print("cloud {} ({} points), reference {} ({} points)\n", args.cloud, r.cloud_points,
             args.ref, r.ref_points);
  PrintStats("accuracy", r.accuracy);
  if (r.surface_accuracy) PrintStats("to surface", *r.surface_accuracy);
  PrintStats("ref->cloud", r.reference_to_cloud);
  fmt::print("completeness  {:.1f}% of reference points have a cloud point within {:g} cm\n",
             100 * r.completeness, args.compare.completeness_m * 100);
  // A SLAM cloud lives in the run's map frame: compared unaligned with a reference in the
  // ground truth's frame, every number above is meaningless. Say so instead of letting a
  // 0% completeness pass for a result.
  if (!aligned && r.accuracy.median > 0.25) {
    fmt::print(
        "warning: the median distance to the reference is {:.2f} m: the cloud is probably not "
        "in the reference's frame; pass --align-run RUN --gt GROUND_TRUTH\n",
        r.accuracy.median);
  }
  if (r.subset_completeness) {
    fmt::print(
        "completeness  {:.1f}% of the {} reference points ({:.1f}%) visible from the "
        "keyframes (depth {:g}..{:g} m, unoccluded)\n",
        100 * *r.subset_completeness, *r.subset_points,
        100.0 * static_cast<double>(*r.subset_points) / static_cast<double>(r.ref_points),
        args.visibility.min_depth_m, args.visibility.max_depth_m);
  }
}

// Completeness against a reference of the observed surfaces only (--observed-ref).
struct ObservedCompleteness {
  std::string ref;
  std::size_t points = 0;
  double completeness = 0;
};

std::vector<ObservedCompleteness> MeasureObservedCompleteness(const CompareArgs& args,
                                                              const PointCloud& cloud) {
  std::vector<ObservedCompleteness> observed;
  for (const std::string& file : args.observed_refs) {
    const PointCloud ref_observed = ReadPly(file);
    if (ref_observed.empty()) throw InputError(file, "the reference cloud has no points");
    observed.push_back(
        {file, ref_observed.size(),
         dense::Completeness(cloud.points, ref_observed.points, args.compare.completeness_m)});
    fmt::print("completeness  {:.1f}% of the {} points of {} (observed surfaces)\n",
               100 * observed.back().completeness, observed.back().points, file);
  }
  return observed;
}

void WriteComparisonJson(const CompareArgs& args, const dense::CompareResult& r,
                         const std::optional<Alignment>& alignment,
                         const std::vector<ObservedCompleteness>& observed) {
  JsonWriter json;
  json.BeginObject();
  json.Member("cloud", args.cloud);
  json.Member("ref", args.ref);
  json.Member("cloud_points", static_cast<std::uint64_t>(r.cloud_points));
  json.Member("ref_points", static_cast<std::uint64_t>(r.ref_points));
  json.Key("alignment");
  if (alignment) {
    json.BeginObject();
    json.Member("method", args.align);
    json.Member("run", args.align_run);
    json.Member("gt", args.gt);
    json.Member("pairs", static_cast<std::uint64_t>(alignment->evaluation.pairs.size()));
    json.Member("trajectory_ate_rmse_m", alignment->evaluation.ate_translation_m.rmse);
    json.Member("scale", alignment->ref_from_slam.scale());
    json.EndObject();
  } else {
    json.Null();
  }
  json.Key("accuracy");
  dense::WriteDistanceStatsJson(r.accuracy, json);
  json.Key("surface_accuracy");
  if (r.surface_accuracy) {
    dense::WriteDistanceStatsJson(*r.surface_accuracy, json);
  } else {
    json.Null();
  }
  json.Key("reference_to_cloud");
  dense::WriteDistanceStatsJson(r.reference_to_cloud, json);
  json.Member("completeness_threshold_m", args.compare.completeness_m);
  json.Member("completeness", r.completeness);
  json.Key("completeness_visible");
  if (r.subset_completeness) {
    json.BeginObject();
    json.Member("visible_ref_points", static_cast<std::uint64_t>(*r.subset_points));
    json.Member("completeness", *r.subset_completeness);
    json.Member("min_depth_m", args.visibility.min_depth_m);
    json.Member("max_depth_m", args.visibility.max_depth_m);
    json.Member("occlusion_tolerance_m", args.visibility.occlusion_tolerance_m);
    json.EndObject();
  } else {
    json.Null();
  }
  json.Key("completeness_observed").BeginArray();
  for (const ObservedCompleteness& o : observed) {
    json.BeginObject();
    json.Member("ref", o.ref);
    json.Member("ref_points", static_cast<std::uint64_t>(o.points));
    json.Member("completeness", o.completeness);
    json.EndObject();
  }
  json.EndArray();
  json.EndObject();
  WriteFileAtomically(args.json, json.str());
}

void RunCompare(const CompareArgs& args) {
  args.compare.Check();
  if (!args.dataset.empty() && args.align_run.empty()) {
    throw OptionError("--dataset (restricted completeness) needs --align-run and --gt");
  }
  PointCloud cloud = ReadCloud(args);
  const PointCloud ref = ReadPly(args.ref);
  if (cloud.empty()) throw InputError(args.cloud, "the cloud has no points");
  if (ref.empty()) throw InputError(args.ref, "the reference cloud has no points");
  const std::optional<Alignment> alignment = AlignCloud(args, &cloud);
  const std::vector<std::uint8_t> visible = args.dataset.empty()
                                                ? std::vector<std::uint8_t>()
                                                : VisibleReferencePoints(args, *alignment, ref);
  const dense::CompareResult r =
      dense::CompareClouds(cloud.points, ref.points, args.compare, visible, ref.normals);
  PrintComparison(args, r, alignment.has_value());
  const std::vector<ObservedCompleteness> observed = MeasureObservedCompleteness(args, cloud);
  if (!args.json.empty()) WriteComparisonJson(args, r, alignment, observed);
  if (!args.hist.empty()) {
    dense::PlotDistanceHistograms({{"cloud -> reference (accuracy)", r.accuracy_distances},
                                   {"reference -> cloud (completeness)", r.completeness_distances}},
                                  fs::path(args.cloud).filename().string(), 10.0, args.hist);
    fmt::print("histogram {}\n", args.hist);
  }
}

}  // namespace

void RegisterCloudCompareCommand(CLI::App& app) {
  auto args = std::make_shared<CompareArgs>();
  auto* cmd = app.add_subcommand(
      "cloud-compare",
      "Accuracy (cloud -> reference nearest-neighbour distances) and completeness (share of "
      "reference points within 5 cm of the cloud) of a point cloud");
  cmd->add_option("--cloud", args->cloud, "The cloud or mesh to evaluate (PLY)")->required();
  cmd->add_option("--mesh-spacing", args->mesh_spacing_m,
                  "A mesh is sampled with about one point per this spacing squared (m)")
      ->capture_default_str();
  cmd->add_option("--ref", args->ref, "The reference cloud (PLY)")->required();
  cmd->add_option("--hist", args->hist, "Write a histogram of the distances (PNG)");
  cmd->add_option("--json", args->json, "Write the results as JSON");
  cmd->add_option("--align-run", args->align_run,
                  "Align the cloud (SLAM world frame) to the reference frame with this run's "
                  "trajectory_body.txt against --gt");
  cmd->add_option("--gt", args->gt,
                  "Ground truth in the reference frame (EuRoC state_groundtruth_estimate0/data.csv "
                  "or TUM groundtruth.txt)");
  cmd->add_option("--align", args->align, "Alignment: se3|sim3")->capture_default_str();
  cmd->add_option("--max-diff", args->max_diff_s, "Pose association tolerance (s)")
      ->capture_default_str();
  cmd->add_option("--write-aligned", args->write_aligned, "Write the aligned cloud (PLY)");
  cmd->add_option("--dataset", args->dataset,
                  "With --align-run: also report completeness over the reference points visible "
                  "from the run's keyframes (this dataset's camera)");
  cmd->add_option("--observed-ref", args->observed_refs,
                  "Also report completeness against these references (the simulator's "
                  "reference_observed.ply: the surfaces the sequence observed)");
  cmd->add_option("--settings", args->settings, "The settings file the run used (if any)");
  cmd->add_option("--max-depth", args->visibility.max_depth_m,
                  "Visibility: largest depth (m; use the dense cloud's)")
      ->capture_default_str();
  cmd->add_option("--min-depth", args->visibility.min_depth_m, "Visibility: smallest depth (m)")
      ->capture_default_str();
  cmd->add_option("--ref-spacing", args->visibility.spacing_m,
                  "Visibility: reference point spacing (m)")
      ->capture_default_str();
  cmd->add_option("--completeness-threshold", args->compare.completeness_m,
                  "A reference point is covered within this distance (m)")
      ->capture_default_str();
  cmd->callback([args] { RunCompare(*args); });
}

}  // namespace pkslam::apps
