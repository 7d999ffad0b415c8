// The reconstruction from tracks on the thesis's synthetic setup: exact tracks give the exact
// trajectory and map (up to a similarity); noisy tracks give reprojection errors of the noise's
// size; the keyframe rules fire where they should; bad requests fail with a clear error.
#include "tracks/reconstruction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "core/util/error.h"
#include "tracks/reconstruction_output.h"
#include "tracks/synthetic_tracks.h"
#include "tracks/track_index.h"

namespace pkslam {
namespace {

TracksTruth TruthOf(const SyntheticTracks& s, double fps) {
  TracksTruth truth;
  for (std::size_t k = 0; k < s.camera_from_world.size(); ++k) {
    truth.trajectory.poses.push_back(
        {std::llround(static_cast<double>(k) / fps * 1e9), s.camera_from_world[k].Inverse()});
  }
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    truth.points.emplace(static_cast<int>(i), s.points[i]);
  }
  return truth;
}

double MeanFrameError(const TracksReconstruction& r, const TrackIndex& index,
                      const PinholeIntrinsics& camera) {
  double sum = 0;
  int n = 0;
  for (int k = 0; k < index.num_frames(); ++k) {
    for (double e : FrameReprojectionErrors(r, index, camera, k)) {
      sum += e;
      ++n;
    }
  }
  return n > 0 ? sum / n : NAN;
}

TEST(TracksReconstruction, ExactTracksGiveTheExactTrajectoryAndMap) {
  SyntheticTracksOptions o;
  const SyntheticTracks s = SimulateTracks(o);
  const TrackIndex index = IndexTracks(s.tracks);
  const TracksReconstruction r = ReconstructFromTracks(s.tracks, index, {});
  EXPECT_EQ(r.lost_frames, 0);
  for (const TracksFrameResult& f : r.frames) EXPECT_TRUE(f.tracked);
  EXPECT_GE(r.num_keyframes, 3);
  const TracksAccuracy a = EvaluateTracksReconstruction(r, index, TruthOf(s, o.fps));
  EXPECT_EQ(a.pairs, 60u);
  // The scene is ~1000 units deep: micro-units are exact up to the solvers' tolerances.
  EXPECT_LT(a.ate_m.rmse, 1e-3);
  EXPECT_LT(a.map_error.rmse, 1e-2);
  EXPECT_EQ(a.map_error.count, s.points.size());
  EXPECT_LT(MeanFrameError(r, index, s.tracks.camera), 1e-4);
}

TEST(TracksReconstruction, NoisyTracksReprojectWithinTheNoise) {
  SyntheticTracksOptions o;
  o.noise_px = 1.0;
  const SyntheticTracks s = SimulateTracks(o);
  const TrackIndex index = IndexTracks(s.tracks);
  TracksReconstructionOptions options;
  options.keyframe_rule = TracksKeyframeRule::kInterval;
  options.baseline.interval_frames = 5;
  const TracksReconstruction r = ReconstructFromTracks(s.tracks, index, options);
  EXPECT_EQ(r.lost_frames, 0);
  // The mean of |2-D Gaussian| with sigma 1 is 1.25; the fit absorbs a little of it at the
  // keyframes, the map's own error adds a little elsewhere.
  const double mean = MeanFrameError(r, index, s.tracks.camera);
  EXPECT_GT(mean, 0.8);
  EXPECT_LT(mean, 1.45);
  const TracksAccuracy a = EvaluateTracksReconstruction(r, index, TruthOf(s, o.fps));
  EXPECT_LT(a.ate_m.rmse, 5.0);  // units of a ~1000-unit scene
}

TEST(TracksReconstruction, IntervalRuleAndDeterminism) {
  SyntheticTracksOptions o;
  o.noise_px = 0.5;
  const SyntheticTracks s = SimulateTracks(o);
  const TrackIndex index = IndexTracks(s.tracks);
  TracksReconstructionOptions options;
  options.keyframe_rule = TracksKeyframeRule::kInterval;
  options.baseline.interval_frames = 5;
  const TracksReconstruction r = ReconstructFromTracks(s.tracks, index, options);
  // Keyframes: the initial pair, then every fifth frame after the second.
  int expected = 2 + (59 - r.init_second) / 5;
  EXPECT_EQ(r.num_keyframes, expected);
  for (int k = r.init_second + 1; k < 60; ++k) {
    EXPECT_EQ(r.frames[static_cast<std::size_t>(k)].keyframe, (k - r.init_second) % 5 == 0) << k;
  }
  const TracksReconstruction again = ReconstructFromTracks(s.tracks, index, options);
  for (std::size_t k = 0; k < r.frames.size(); ++k) {
    EXPECT_EQ(r.frames[k].camera_from_world.Matrix(), again.frames[k].camera_from_world.Matrix());
  }
}

TEST(TracksReconstruction, AutomaticPairHasBaselineAndFirstTwoDoesNot) {
  SyntheticTracksOptions o;
  o.noise_px = 1.0;
  const SyntheticTracks s = SimulateTracks(o);
  const TrackIndex index = IndexTracks(s.tracks);
  const TracksReconstruction automatic = ReconstructFromTracks(s.tracks, index, {});
  EXPECT_GT(automatic.init_second, 1);
  EXPECT_GE(automatic.init.median_parallax_deg, 2.0);
  EXPECT_FALSE(automatic.init_refused.empty());
  TracksReconstructionOptions first_two;
  first_two.init_mode = TracksInitMode::kFirstTwo;
  const TracksReconstruction thesis = ReconstructFromTracks(s.tracks, index, first_two);
  EXPECT_EQ(thesis.init_second, 1);
  EXPECT_LT(thesis.init.median_parallax_deg, 0.5);
  // The thesis's finding: the small baseline gets depth wrong and the errors grow several-fold.
  EXPECT_GT(MeanFrameError(thesis, index, s.tracks.camera),
            3 * MeanFrameError(automatic, index, s.tracks.camera));
}

TEST(TracksReconstruction, RefusesWhatItCannotDo) {
  SyntheticTracksOptions o;
  o.num_frames = 3;
  const SyntheticTracks s = SimulateTracks(o);
  const TrackIndex index = IndexTracks(s.tracks);
  // Three frames 5 units apart never reach 2 degrees of parallax.
  EXPECT_THROW(ReconstructFromTracks(s.tracks, index, {}), Error);
  TracksReconstructionOptions fixed;
  fixed.init_mode = TracksInitMode::kFixed;
  fixed.init_second_frame = 7;
  EXPECT_THROW(ReconstructFromTracks(s.tracks, index, fixed), OptionError);
  TracksReconstructionOptions bad;
  bad.local_window = 1;
  EXPECT_THROW(ReconstructFromTracks(s.tracks, index, bad), OptionError);
}

}  // namespace
}  // namespace pkslam
