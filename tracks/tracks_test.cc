// Tracks: the file format round-trips and refuses malformed files naming file and line; the
// generator follows the thesis's setup (points in the box, all seen in the first frame, noise
// of the requested size) and is reproducible from its seed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/util/error.h"
#include "io/track_file.h"
#include "tests/support/test_data.h"
#include "tracks/synthetic_tracks.h"

namespace pkslam {
namespace {

std::filesystem::path TempFile(const std::string& name) {
  static const std::filesystem::path dir = testing::MakeTempDir("tracks");
  return dir / name;
}

TEST(SyntheticTracks, FollowTheThesisSetupAndTheSeed) {
  SyntheticTracksOptions options;
  const SyntheticTracks a = SimulateTracks(options);
  ASSERT_GT(a.points.size(), 100u);
  EXPECT_EQ(static_cast<int>(a.points.size()) + a.dropped_points, 200);
  for (const Eigen::Vector3d& p : a.points) {
    EXPECT_TRUE(p.x() >= 300 && p.x() <= 800 && p.y() >= 300 && p.y() <= 800);
    EXPECT_TRUE(p.z() >= 600 && p.z() <= 1500);
  }
  // Frame 0 sees every kept point; the file format's rules hold.
  int in_first = 0;
  for (const TrackObservation& o : a.tracks.observations) in_first += o.frame == 0 ? 1 : 0;
  EXPECT_EQ(in_first, static_cast<int>(a.points.size()));
  EXPECT_EQ(a.tracks.NumFrames(), 60);
  // Noise-free projections are exact; noisy ones differ by the requested sigma.
  options.noise_px = 2.0;
  const SyntheticTracks noisy = SimulateTracks(options);
  ASSERT_EQ(noisy.points, a.points);
  double sum_sq = 0;
  int n = 0;
  for (std::size_t i = 0; i < noisy.tracks.observations.size() && i < a.tracks.observations.size();
       ++i) {
    const auto& x = noisy.tracks.observations[i];
    const auto& y = a.tracks.observations[i];
    if (x.frame != y.frame || x.track != y.track) continue;
    sum_sq += (x.u - y.u) * (x.u - y.u) + (x.v - y.v) * (x.v - y.v);
    n += 2;
  }
  ASSERT_GT(n, 1000);
  EXPECT_NEAR(std::sqrt(sum_sq / n), 2.0, 0.1);
  EXPECT_EQ(SimulateTracks(options).tracks.observations.size(), noisy.tracks.observations.size());
  options.shape = "spiral";
  EXPECT_THROW(SimulateTracks(options), OptionError);
}

TEST(SyntheticTracks, ReplayAGroundTruthPath) {
  // 3 s of a 200 Hz path along x, yawing slowly; resampled at 20 Hz from 1 s in.
  Trajectory gt;
  for (int i = 0; i <= 800; ++i) {
    gt.poses.push_back(
        {1'000'000'000'000LL + i * 5'000'000LL,
         SE3d(SO3d::Exp(Eigen::Vector3d(0, 0.001 * i, 0)), Eigen::Vector3d(0.002 * i, 0, 0))});
  }
  SyntheticTracksOptions options;
  options.num_points = 500;
  ReplayPath(gt, SE3d(), 20, 1.0, 2.0, &options);
  ASSERT_EQ(options.replay_world_from_camera.size(), 40u);
  EXPECT_DOUBLE_EQ(options.replay_times_s.front(), 1001.0);
  const SyntheticTracks s = SimulateTracks(options);
  EXPECT_EQ(s.points.size(), 500u);
  EXPECT_EQ(s.dropped_points, 0);
  EXPECT_EQ(s.tracks.NumFrames(), 40);
  for (const TrackObservation& o : s.tracks.observations) {
    const Eigen::Vector3d c = s.camera_from_world[static_cast<std::size_t>(o.frame)] *
                              s.points[static_cast<std::size_t>(o.track)];
    const Eigen::Vector2d uv = options.camera.Project(c);
    EXPECT_NEAR(uv.x(), o.u, 1e-9);
    EXPECT_NEAR(o.t_s, options.replay_times_s[static_cast<std::size_t>(o.frame)], 0);
  }
  // Every point is seen by the frame whose ray drew it, so each track has an observation.
  std::vector<int> seen(500, 0);
  for (const TrackObservation& o : s.tracks.observations) ++seen[static_cast<std::size_t>(o.track)];
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 0), 0);
  EXPECT_THROW(ReplayPath(gt, SE3d(), 20, 10.0, 1.0, &options), Error);  // past the end
}

TEST(TrackFile, RoundTripsAndRefusesMalformedFiles) {
  SyntheticTracksOptions options;
  options.noise_px = 1.0;
  options.shape = "circle";
  const SyntheticTracks s = SimulateTracks(options);
  const auto file = TempFile("round.txt");
  WriteTrackFile(s.tracks, file);
  const TrackSet back = ReadTrackFile(file);
  ASSERT_EQ(back.observations.size(), s.tracks.observations.size());
  EXPECT_EQ(back.width, 1280);
  EXPECT_EQ(back.camera.fx, 700);
  for (std::size_t i = 0; i < back.observations.size(); ++i) {
    EXPECT_EQ(back.observations[i].track, s.tracks.observations[i].track);
    EXPECT_NEAR(back.observations[i].u, s.tracks.observations[i].u, 1e-6);
  }
  auto expect_line = [](const std::string& text, std::size_t line) {
    const auto bad = TempFile("bad.txt");
    std::ofstream(bad) << text;
    try {
      ReadTrackFile(bad);
      ADD_FAILURE() << "accepted:\n" << text;
    } catch (const InputError& e) {
      EXPECT_EQ(e.line(), line) << e.what();
    }
  };
  const std::string head = "# pkslam tracks v1\ncamera 700 700 640 360 1280 720\n";
  expect_line("hello\n", 1);
  expect_line("# pkslam tracks v1\n0 0.0 1 10 10\n", 2);     // no camera yet
  expect_line(head + "0 0.0 1 10\n", 3);                     // four fields
  expect_line(head + "1 0.05 1 10 10\n0 0.0 2 10 10\n", 4);  // frame goes back
  expect_line(head + "0 0.0 1 10 10\n0 0.0 1 11 11\n", 4);   // track twice
  expect_line(head + "0 0.0 1 10 10\n1 0.0 1 11 11\n", 4);   // time stands still
  expect_line(head + "0 0.0 x 10 10\n", 3);                  // not a number
}

}  // namespace
}  // namespace pkslam
