// pkslam tracks simulate: seed 002's synthetic tracks (tracks/). The reconstruction
// (`tracks reconstruct`) and `tracks export` follow with issue 24.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "apps/commands.h"
#include "core/util/error.h"
#include "core/util/output_file.h"
#include "io/trajectory.h"
#include "tracks/synthetic_tracks.h"
#include "tracks/track_file.h"

namespace pkslam::apps {

void RegisterTracksCommand(CLI::App& app) {
  auto options = std::make_shared<SyntheticTracksOptions>();
  auto out = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("tracks", "Reconstruction from 2-D tracks (seed 002)");
  cmd->require_subcommand(1);
  auto* sim = cmd->add_subcommand(
      "simulate",
      "The thesis's synthetic tracks: random points in a box, a camera path, projections with "
      "Gaussian noise; writes OUT/tracks.txt, truth_trajectory.txt, truth_points.txt");
  sim->add_option("--out", *out, "Output directory")->required();
  sim->add_option("--noise", options->noise_px, "Pixel noise sigma")->capture_default_str();
  sim->add_option("--seed", options->seed, "Random seed")->capture_default_str();
  sim->add_option("--points", options->num_points, "Points drawn")->capture_default_str();
  sim->add_option("--frames", options->num_frames, "Frames")->capture_default_str();
  sim->add_option("--shape", options->shape, "Camera path: line | circle")->capture_default_str();
  sim->add_option("--step", options->step, "Camera motion per frame (thesis units)")
      ->capture_default_str();
  sim->callback([options, out] {
    const SyntheticTracks s = SimulateTracks(*options);
    const std::filesystem::path dir = *out;
    std::filesystem::create_directories(dir);
    WriteTrackFile(s.tracks, dir / "tracks.txt");
    Trajectory truth;
    for (std::size_t k = 0; k < s.camera_from_world.size(); ++k) {
      truth.poses.push_back({static_cast<std::int64_t>(std::llround(k / options->fps * 1e9)),
                             s.camera_from_world[k].Inverse()});
    }
    WriteTrajectoryTum(truth, dir / "truth_trajectory.txt");
    std::string points = "# track x y z\n";
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      points += fmt::format("{} {:.9g} {:.9g} {:.9g}\n", i, s.points[i].x(), s.points[i].y(),
                            s.points[i].z());
    }
    WriteFileAtomically(dir / "truth_points.txt", points);
    std::cout << fmt::format(
        "{} frames, {} tracks ({} points dropped: not in the first frame), {} observations, "
        "{} projections outside the image left out; outputs in {}\n",
        s.camera_from_world.size(), s.points.size(), s.dropped_points, s.tracks.observations.size(),
        s.outside_projections, dir.string());
  });
}

}  // namespace pkslam::apps
