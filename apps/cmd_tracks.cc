// pkslam tracks: PTAM-style reconstruction from 2-D tracks (tracks/): `simulate` (the source
// study's synthetic tracks, docs/tracks.md), `reconstruct` (trajectory, map, errors, report) and `export` (tracks of a
// simulated sequence or of a pkslam run).
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "bench/process.h"
#include "core/util/error.h"
#include "core/util/output_file.h"
#include "core/util/progress.h"
#include "core/util/project_file.h"
#include "io/rigid_transform_file.h"
#include "io/track_file.h"
#include "io/trajectory.h"
#include "tracks/reconstruction.h"
#include "tracks/reconstruction_output.h"
#include "tracks/synthetic_tracks.h"
#include "tracks/track_export.h"

namespace pkslam::apps {

namespace {

// report.html and its PNGs from the run's files (tracks/report.py, matplotlib).
std::filesystem::path WriteTracksReport(const std::filesystem::path& out,
                                        const std::filesystem::path& truth_dir) {
  const std::filesystem::path script = FindProjectFile("tracks/report.py");
  if (!std::filesystem::exists(script)) throw Error("report script not found: " + script.string());
  std::vector<std::string> argv = {"/usr/bin/python3", script.string(), "--run", out.string()};
  if (!truth_dir.empty()) argv.insert(argv.end(), {"--truth", truth_dir.string()});
  const std::filesystem::path log = out / "report.log";
  const bench::ProcessResult p = bench::RunProcess(argv, log, 600.0);
  if (!p.ok()) {
    throw Error(fmt::format("tracks/report.py failed ({}); see {}", p.Describe(), log.string()));
  }
  std::filesystem::remove(log);
  return out / "report.html";
}

struct SimulateArgs {
  std::string out;
  std::string trajectory;
  std::string body_from_camera;
  double start_s = 0, duration_s = 0;
};

void RegisterSimulate(CLI::App* cmd) {
  auto options = std::make_shared<SyntheticTracksOptions>();
  auto args = std::make_shared<SimulateArgs>();
  auto* sim = cmd->add_subcommand(
      "simulate",
      "Synthetic tracks as in the PTAM study behind this module (docs/tracks.md): random points in a box, a camera path (line, circle or a "
      "replayed ground truth), projections with Gaussian noise; writes OUT/tracks.txt, "
      "truth_trajectory.txt, truth_points.txt");
  sim->add_option("--out", args->out, "Output directory")->required();
  sim->add_option("--noise", options->noise_px, "Pixel noise sigma")->capture_default_str();
  sim->add_option("--seed", options->seed, "Random seed")->capture_default_str();
  sim->add_option("--points", options->num_points, "Points drawn")->capture_default_str();
  sim->add_option("--frames", options->num_frames, "Frames")->capture_default_str();
  sim->add_option("--fps", options->fps, "Frame rate")->capture_default_str();
  sim->add_option("--shape", options->shape, "Camera path: line | circle")->capture_default_str();
  sim->add_option("--step", options->step, "Camera motion per frame (scene units: the points lie about 1000 units away)")
      ->capture_default_str();
  sim->add_option("--trajectory", args->trajectory,
                  "Replay this ground truth (TUM or EuRoC csv, world_from_body) at --fps instead "
                  "of --shape; points along random rays at --depth-min..--depth-max");
  sim->add_option("--start", args->start_s, "Replay: seconds into the trajectory")
      ->capture_default_str();
  sim->add_option("--duration", args->duration_s, "Replay: seconds (0: to the end)")
      ->capture_default_str();
  sim->add_option("--body-from-camera", args->body_from_camera,
                  "Replay: camera extrinsics (4x4 file, io/rigid_transform_file.h); default "
                  "identity (EuRoC's cam0 looks along the body z axis)");
  sim->add_option("--depth-min", options->replay_depth_min, "Replay: nearest point depth")
      ->capture_default_str();
  sim->add_option("--depth-max", options->replay_depth_max, "Replay: farthest point depth")
      ->capture_default_str();
  sim->callback([options, args] {
    if (!args->trajectory.empty()) {
      const SE3d body_from_camera =
          args->body_from_camera.empty() ? SE3d() : ReadRigidTransform(args->body_from_camera);
      ReplayPath(ReadTrajectory(args->trajectory), body_from_camera, options->fps, args->start_s,
                 args->duration_s, options.get());
    }
    const SyntheticTracks s = SimulateTracks(*options);
    const std::filesystem::path dir = args->out;
    std::filesystem::create_directories(dir);
    WriteTrackFile(s.tracks, dir / "tracks.txt");
    Trajectory truth;
    for (std::size_t k = 0; k < s.camera_from_world.size(); ++k) {
      const double t = options->replay_times_s.empty() ? static_cast<double>(k) / options->fps
                                                       : options->replay_times_s[k];
      truth.poses.push_back({std::llround(t * 1e9), s.camera_from_world[k].Inverse()});
    }
    WriteTrajectoryTum(truth, dir / "truth_trajectory.txt");
    TrackPoints points;
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      points.emplace_back(static_cast<int>(i), s.points[i]);
    }
    WriteTrackPoints(points, dir / "truth_points.txt");
    std::cout << fmt::format(
        "{} frames, {} tracks ({} points dropped: not in the first frame), {} observations, "
        "{} projections outside the image left out; outputs in {}\n",
        s.camera_from_world.size(), s.points.size(), s.dropped_points, s.tracks.observations.size(),
        s.outside_projections, dir.string());
  });
}

struct ReconstructArgs {
  std::string tracks;
  std::string out;
  std::string keyframes = "ptam";
  std::string init = "auto";
  std::string truth;
  std::vector<int> histogram_frames = {1, 49};
  bool no_report = false;
  bool quiet = false;
};

void RegisterReconstruct(CLI::App* cmd) {
  auto args = std::make_shared<ReconstructArgs>();
  auto o = std::make_shared<TracksReconstructionOptions>();
  auto* rec = cmd->add_subcommand(
      "reconstruct",
      "Trajectory and map from tracks: two-view initialisation, PnP, triangulation, local and "
      "global BA; writes OUT/trajectory.txt (TUM), map.ply, stats.json, frames.csv, "
      "report.html");
  rec->add_option("tracks", args->tracks, "Tracks file, or a folder with tracks.txt")->required();
  rec->add_option("--out", args->out, "Output directory")->required();
  rec->add_option("--keyframes", args->keyframes, "Keyframe rule: ptam|match-count|interval|ratio")
      ->capture_default_str();
  rec->add_option("--init", args->init,
                  "Initial pair: auto (first pair with enough baseline) | first-two (frames 1 "
                  "and 2, the PTAM study's rule) | fixed (with --init-frame)")
      ->capture_default_str();
  rec->add_option("--init-frame", o->init_second_frame, "Second frame of a fixed initial pair");
  rec->add_option("--init-parallax", o->init_min_parallax_deg,
                  "auto: median ray angle (deg) the initial pair needs")
      ->capture_default_str();
  rec->add_option("--init-search", o->init_search_frames, "auto: later frames tried")
      ->capture_default_str();
  rec->add_option("--sigma", o->two_view.sigma, "Pixel noise sigma of the chi2 gates")
      ->capture_default_str();
  rec->add_option("--interval", o->baseline.interval_frames, "interval: frames between keyframes")
      ->capture_default_str();
  rec->add_option("--ptam-frames", o->baseline.ptam_min_frames, "ptam: frames since the last")
      ->capture_default_str();
  rec->add_option("--ptam-distance", o->baseline.ptam_min_distance_ratio,
                  "ptam: distance moved / median depth")
      ->capture_default_str();
  rec->add_option("--min-matches", o->baseline.match_count_min,
                  "match-count: keyframe below this many points shared with the last keyframe")
      ->capture_default_str();
  rec->add_option("--ratio", o->ratio_max, "ratio: keyframe when map matches < RATIO x new tracks")
      ->capture_default_str();
  rec->add_option("--starving", o->starving_share,
                  "every rule: keyframe when map matches fall below this share of the last "
                  "keyframe's")
      ->capture_default_str();
  rec->add_option("--local-window", o->local_window, "Keyframes per local bundle adjustment")
      ->capture_default_str();
  rec->add_flag(
      "--no-global-ba", [o](std::int64_t) { o->global_ba = false; },
      "Skip the final global bundle adjustment");
  rec->add_flag(
      "--no-refine-frames", [o](std::int64_t) { o->refine_frames = false; },
      "Keep each frame's online pose (relative to its keyframe) instead of re-posing "
      "it against the final map");
  rec->add_option("--seed", o->seed, "RANSAC seed")->capture_default_str();
  rec->add_option("--truth", args->truth,
                  "Folder with truth_trajectory.txt (+ truth_points.txt); default: the tracks' "
                  "folder when it has them");
  rec->add_option("--histogram-frames", args->histogram_frames,
                  "Frames whose reprojection-error histograms the report shows (0-based; the "
                  "default 1 and 49 are the PTAM study's frames 2 and 50)")
      ->capture_default_str();
  rec->add_flag("--no-report", args->no_report, "Skip report.html and its plots");
  rec->add_flag("--quiet", args->quiet, "No progress");
  rec->callback([args, o, rec] {
    namespace fs = std::filesystem;
    o->keyframe_rule = ParseTracksKeyframeRule(args->keyframes);
    o->init_mode = ParseTracksInitMode(args->init);
    if (rec->count("--init-frame") > 0 && o->init_mode != TracksInitMode::kFixed) {
      throw OptionError("--init-frame needs --init fixed");
    }
    o->Check();
    fs::path file = args->tracks;
    if (fs::is_directory(file)) file /= "tracks.txt";
    const TrackSet tracks = ReadTrackFile(file);
    const TrackIndex index = IndexTracks(tracks);
    const fs::path truth_dir = args->truth.empty() ? file.parent_path() : fs::path(args->truth);
    if (!args->truth.empty() && !fs::exists(truth_dir / "truth_trajectory.txt")) {
      throw InputError(truth_dir / "truth_trajectory.txt", "not found (--truth)");
    }
    const std::optional<TracksTruth> truth = ReadTracksTruth(truth_dir);
    Progress progress("reconstruct", static_cast<std::size_t>(index.num_frames()), args->quiet);
    const TracksReconstruction r = ReconstructFromTracks(tracks, index, *o, [&](int done, int) {
      progress.Add(static_cast<std::size_t>(done) - progress.done());
    });
    progress.Finish();
    std::optional<TracksAccuracy> accuracy;
    if (truth) accuracy = EvaluateTracksReconstruction(r, index, *truth);
    TracksOutputOptions output;
    output.histogram_frames = args->histogram_frames;
    output.options = o.get();
    const fs::path out = args->out;
    WriteTracksReconstruction(out, tracks, index, r, accuracy, output);
    std::string line = fmt::format(
        "{} of {} frames tracked, {} keyframes, {} map points; initial pair {}-{} (parallax "
        "{:.2f} deg); {:.2f} s",
        index.num_frames() - r.lost_frames, index.num_frames(), r.num_keyframes,
        std::count_if(r.points.begin(), r.points.end(),
                      [](const auto& p) { return p.has_value(); }),
        r.init_first, r.init_second, r.init.median_parallax_deg, r.seconds_total);
    if (accuracy) {
      line += fmt::format("; ATE (Sim3) {:.4g} (truth units)", accuracy->ate_m.rmse);
      if (accuracy->map_error.count > 0) {
        line += fmt::format(", map error {:.4g} (median depth {:.4g})", accuracy->map_error.rmse,
                            accuracy->median_truth_depth);
      }
    }
    std::cout << line << "\n";
    if (!args->no_report) {
      const fs::path report = WriteTracksReport(out, truth ? truth_dir : fs::path());
      std::cout << "report: " << report.string() << "\n";
    }
    if (r.lost_frames > 0) {
      std::cout << fmt::format("warning: {} frame(s) not tracked (see {}/frames.csv)\n",
                               r.lost_frames, out.string());
    }
  });
}

struct ExportArgs {
  std::string simulated;
  std::string run;
  std::string dataset;
  std::string out;
  bool every_frame = false;
};

void RegisterExport(CLI::App* cmd) {
  auto args = std::make_shared<ExportArgs>();
  auto o = std::make_shared<SimulatedTracksExportOptions>();
  auto* ex = cmd->add_subcommand(
      "export",
      "Tracks of a simulated sequence (--simulated SEQ, rendered with `simulate --tracks N`: "
      "exact projections + Gaussian noise) or the keyframe observations of a pkslam run (--run "
      "RUN, its sparse_model.txt); writes OUT/tracks.txt and the truth when known");
  auto* sim = ex->add_option("--simulated", args->simulated, "Simulated EuRoC sequence");
  auto* run = ex->add_option("--run", args->run, "pkslam run output folder");
  sim->excludes(run);
  ex->add_option("--dataset", args->dataset,
                 "--run: the dataset it ran on, for the truth (cam0 at each keyframe)");
  ex->add_flag("--every-frame", args->every_frame,
               "--run: every tracked frame's matched map points (the run's frame_tracks.txt, from "
               "`run --frame-tracks`) instead of the keyframe observations");
  ex->add_option("--out", args->out, "Output directory")->required();
  ex->add_option("--noise", o->noise_px, "--simulated: pixel noise sigma")->capture_default_str();
  ex->add_option("--seed", o->seed, "--simulated: noise seed")->capture_default_str();
  ex->add_option("--every", o->every, "--simulated: keep every N-th frame")->capture_default_str();
  ex->add_option("--start", o->start_s, "--simulated: seconds after the first frame")
      ->capture_default_str();
  ex->add_option("--duration", o->duration_s, "--simulated: seconds (0: to the end)")
      ->capture_default_str();
  ex->callback([args, o] {
    if (args->simulated.empty() == args->run.empty()) {
      throw OptionError("tracks export: give --simulated SEQ or --run RUN");
    }
    const ExportedTracks e = args->simulated.empty()
                                 ? ExportRunTracks(args->run, args->dataset, args->every_frame)
                                 : ExportSimulatedTracks(args->simulated, *o);
    WriteExportedTracks(e, args->out);
    std::cout << fmt::format("{} frames, {} observations{}; written to {}\n", e.tracks.NumFrames(),
                             e.tracks.observations.size(),
                             e.truth.poses.empty() ? " (no truth)" : ", with truth", args->out);
  });
}

}  // namespace

void RegisterTracksCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("tracks", "Trajectory and map from 2-D point tracks (PTAM-style: two-view start, PnP, "
                                 "triangulation, keyframes; docs/tracks.md)");
  cmd->require_subcommand(1);
  RegisterSimulate(cmd);
  RegisterReconstruct(cmd);
  RegisterExport(cmd);
}

}  // namespace pkslam::apps
