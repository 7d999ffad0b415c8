// The thesis's initialisation on hand-made cases: the four [R | +-u3] candidates of an
// essential matrix, the one that cheirality selects, linear triangulation of exact points, and
// the two-view reconstruction from tracks with its baseline test.
#include "tracks/tracks_two_view.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "estimators/two_view/two_view_motion.h"
#include "tracks/synthetic_tracks.h"
#include "tracks/track_index.h"

namespace pkslam {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

struct HandMadeCase {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;          // unit
  std::vector<Eigen::Vector3d> points;  // camera 1
};

// Camera 2 is 5 degrees yawed and moved mostly sideways; points on a 5 x 5 grid 4-8 m ahead.
HandMadeCase MakeCase() {
  HandMadeCase c;
  c.rotation = Eigen::AngleAxisd(5.0 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  c.translation = Eigen::Vector3d(-1.0, 0.05, 0.1).normalized();
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) c.points.emplace_back(i - 2.0, j - 2.0, 4.0 + i + 0.5 * j);
  }
  return c;
}

TEST(TracksTwoView, OneOfTheFourCandidatesPutsThePointsInFrontOfBothCameras) {
  const HandMadeCase c = MakeCase();
  const Eigen::Matrix3d e = Skew(c.translation) * c.rotation;
  const std::vector<two_view::Motion> motions = two_view::DecomposeEssential(e);
  ASSERT_EQ(motions.size(), 4u);
  int winners = 0;
  for (const two_view::Motion& m : motions) {
    EXPECT_NEAR(m.rotation.determinant(), 1.0, 1e-12);
    EXPECT_NEAR(m.translation.norm(), 1.0, 1e-12);
    int in_front = 0;
    for (const Eigen::Vector3d& p : c.points) {
      const Eigen::Vector2d x1 = p.head<2>() / p.z();
      const Eigen::Vector3d q = c.rotation * p + c.translation;
      const Eigen::Vector2d x2 = q.head<2>() / q.z();
      const Eigen::Vector3d t = two_view::TriangulateLinear(x1, x2, m);
      in_front += t.z() > 0 && (m.rotation * t + m.translation).z() > 0 ? 1 : 0;
    }
    if (in_front == static_cast<int>(c.points.size())) {
      ++winners;
      EXPECT_LT((m.rotation - c.rotation).norm(), 1e-9);
      EXPECT_LT((m.translation - c.translation).norm(), 1e-9);
    } else {
      // The other three put every point behind one of the cameras.
      EXPECT_EQ(in_front, 0);
    }
  }
  EXPECT_EQ(winners, 1);
}

TEST(TracksTwoView, LinearTriangulationRecoversExactPoints) {
  const HandMadeCase c = MakeCase();
  two_view::Motion m{c.rotation, c.translation};
  for (const Eigen::Vector3d& p : c.points) {
    const Eigen::Vector3d q = c.rotation * p + c.translation;
    const Eigen::Vector3d t =
        two_view::TriangulateLinear(p.head<2>() / p.z(), q.head<2>() / q.z(), m);
    EXPECT_LT((t - p).norm(), 1e-9 * p.norm());
  }
}

TEST(TracksTwoView, ReconstructsExactTracksUpToScale) {
  SyntheticTracksOptions o;
  const SyntheticTracks s = SimulateTracks(o);
  const TrackIndex index = IndexTracks(s.tracks);
  const TracksTwoViewResult r =
      ReconstructTwoViewTracks(index.frames[0], index.frames[20], s.tracks.camera, {});
  ASSERT_TRUE(r.ok) << r.failure;
  const SE3d truth = s.camera_from_world[20] * s.camera_from_world[0].Inverse();
  EXPECT_LT((r.camera2_from_camera1.translation() - truth.translation().normalized()).norm(), 1e-6);
  EXPECT_LT((r.camera2_from_camera1.RotationMatrix() - truth.RotationMatrix()).norm(), 1e-6);
  const double scale = truth.translation().norm();
  int checked = 0;
  for (std::size_t i = 0; i < r.tracks.size(); ++i) {
    if (!r.triangulated[i]) continue;
    const Eigen::Vector3d p =
        s.camera_from_world[0] *
        s.points[static_cast<std::size_t>(index.track_ids[static_cast<std::size_t>(r.tracks[i])])];
    EXPECT_LT((r.points_camera1[i] * scale - p).norm(), 1e-6 * p.norm());
    ++checked;
  }
  EXPECT_EQ(checked, static_cast<int>(r.tracks.size()));
}

TEST(TracksTwoView, TheBaselineTestRefusesNeighbouringFrames) {
  SyntheticTracksOptions o;
  o.noise_px = 1.0;
  const SyntheticTracks s = SimulateTracks(o);
  const TrackIndex index = IndexTracks(s.tracks);
  TracksTwoViewOptions strict;
  strict.min_parallax_deg = 2.0;
  const TracksTwoViewResult near =
      ReconstructTwoViewTracks(index.frames[0], index.frames[1], s.tracks.camera, strict);
  EXPECT_FALSE(near.ok);
  const TracksTwoViewResult wide =
      ReconstructTwoViewTracks(index.frames[0], index.frames[20], s.tracks.camera, strict);
  EXPECT_TRUE(wide.ok) << wide.failure;
  EXPECT_GT(wide.median_parallax_deg, 2.0);
}

}  // namespace
}  // namespace pkslam
