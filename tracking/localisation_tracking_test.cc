// Localisation-only tracking: its match counts and visual-odometry points on a synthetic stereo
// frame, and its policy with scripted moves (which move is tried, which pose the frame keeps).
#include "tracking/localisation_tracking.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

class LocalisationTrackingTest : public ::testing::Test {
 protected:
  LocalisationTrackingTest()
      : rig_(testing::MakeStereoRig()),
        scene_(testing::MakeScene(300, 4)),
        frame_(testing::MakeFrame(scene_, rig_, SE3d(), 1, 0, testing::FrameOptions(),
                                  &point_of_keypoint_)) {
    frame_.SetPose(SE3d());
    frame_.map_points.assign(frame_.size(), nullptr);
    frame_.outliers.assign(frame_.size(), 0);
  }

  // The first `n` keypoints matched to temporary points (no observations), as odometry leaves
  // them; the pose moved to `x` metres along x.
  void Odometry(int n, double x) {
    frame_.SetPose(SE3d(SO3d(), Eigen::Vector3d(x, 0, 0)));
    frame_.map_points.assign(frame_.size(), nullptr);
    frame_.outliers.assign(frame_.size(), 0);
    for (int i = 0; i < n; ++i) {
      frame_.map_points[i] = MapPoint::Temporary(scene_.points_world[0], frame_.descriptors()[i]);
    }
  }

  static LocalisationFrame Tracked() {
    LocalisationFrame f;
    f.last_tracked = true;
    f.has_velocity = true;
    f.after_relocalisation_gap = true;
    f.odometry_possible = true;
    return f;
  }

  // Moves that record their calls; each returns what the test set.
  LocalisationMoves Moves() {
    return {[this] {
              calls_.push_back("motion");
              Odometry(25, 0.1);
              return motion_;
            },
            [this] {
              calls_.push_back("reference");
              return reference_;
            },
            [this] {
              calls_.push_back("relocalise");
              return relocalise_;
            },
            [this] {
              calls_.push_back("local_map");
              frame_.SetPose(SE3d(SO3d(), Eigen::Vector3d(9, 0, 0)));  // what a search leaves
              frame_.map_points.assign(frame_.size(), nullptr);
              return local_map_;
            }};
  }

  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticScene scene_;
  std::vector<int> point_of_keypoint_;
  Frame frame_;
  LocalisationTracking tracking_;
  std::vector<std::string> calls_;
  bool motion_ = true, reference_ = true, relocalise_ = false, local_map_ = false;
};

TEST_F(LocalisationTrackingTest, InlierMatchesCountMapPointsApartFromOdometryPoints) {
  Odometry(3, 0);
  Atlas atlas;
  const testing::SyntheticMap map =
      testing::MakeMap(&atlas, scene_, rig_, {SE3d(), SE3d(SO3d(), Eigen::Vector3d(0.2, 0, 0))},
                       testing::FrameOptions());
  int observed = 0;
  for (const MapPointPtr& mp : map.point_of_scene_index) {
    if (mp && observed < 2) frame_.map_points[10 + observed++] = mp;
  }
  ASSERT_EQ(observed, 2);
  frame_.outliers[11] = 1;
  EXPECT_EQ(InlierMatches(frame_, /*map_only=*/false), 4);  // 3 temporary + 1 observed
  EXPECT_EQ(InlierMatches(frame_, /*map_only=*/true), 1);
}

TEST_F(LocalisationTrackingTest, OdometryPointsAreTheNearestDepthsToppedUpToTheMinimum) {
  const double th_depth = rig_->th_depth;  // 3.85 m; the scene lies 3-8 m away
  int closer = 0;
  std::vector<float> depths;
  for (int i = 0; i < frame_.size(); ++i) {
    if (!frame_.HasDepth(i)) continue;
    depths.push_back(frame_.depth()[i]);
    if (frame_.depth()[i] <= th_depth) ++closer;
  }
  ASSERT_GT(closer, 5);
  const int min_points = closer + 20;
  ASSERT_LT(min_points, static_cast<int>(depths.size()));
  std::sort(depths.begin(), depths.end());
  AddVisualOdometryPoints(th_depth, min_points, &frame_);
  int added = 0;
  for (int i = 0; i < frame_.size(); ++i) {
    const MapPointPtr& mp = frame_.map_points[i];
    if (!mp) continue;
    ++added;
    EXPECT_EQ(mp->NumObservations(), 0);
    EXPECT_LE(frame_.depth()[i], depths[min_points - 1]);  // the nearest first
    EXPECT_LT((mp->position() - *frame_.UnprojectStereo(i)).norm(), 1e-9);
  }
  EXPECT_EQ(added, min_points);  // all closer than th_depth, topped up to min_points
}

TEST_F(LocalisationTrackingTest, AFrameAfterALostOneIsPlacedOnlyByTheMap) {
  LocalisationFrame lost = Tracked();
  lost.last_tracked = false;
  relocalise_ = true;
  local_map_ = true;
  EXPECT_TRUE(tracking_.Track(lost, Moves(), &frame_));
  EXPECT_EQ(calls_, (std::vector<std::string>{"relocalise", "local_map"}));
  relocalise_ = false;
  calls_.clear();
  EXPECT_FALSE(tracking_.Track(lost, Moves(), &frame_));
  EXPECT_EQ(calls_, (std::vector<std::string>{"relocalise"}));
  EXPECT_FALSE(tracking_.visual_odometry());
}

TEST_F(LocalisationTrackingTest, WhereTheMapRunsOutOfViewOdometryKeepsItsPose) {
  // The motion model tracks the frame (25 odometry matches), the local map search fails.
  EXPECT_TRUE(tracking_.Track(Tracked(), Moves(), &frame_));
  EXPECT_EQ(calls_, (std::vector<std::string>{"motion", "local_map"}));
  EXPECT_TRUE(tracking_.visual_odometry());
  EXPECT_NEAR(frame_.camera_from_world().translation().x(), 0.1, 1e-12);  // the odometry pose
  EXPECT_EQ(InlierMatches(frame_, false), 25);
  // Monocular: no depth, no odometry: the camera is lost.
  LocalisationTracking mono;
  LocalisationFrame f = Tracked();
  f.odometry_possible = false;
  EXPECT_FALSE(mono.Track(f, Moves(), &frame_));
  EXPECT_FALSE(mono.visual_odometry());
}

TEST_F(LocalisationTrackingTest, InOdometryARelocalisationWinsAndNothingMeansLost) {
  ASSERT_TRUE(tracking_.Track(Tracked(), Moves(), &frame_));
  ASSERT_TRUE(tracking_.visual_odometry());
  // Still no map in view: odometry goes on from the motion model's pose.
  calls_.clear();
  EXPECT_TRUE(tracking_.Track(Tracked(), Moves(), &frame_));
  EXPECT_EQ(calls_, (std::vector<std::string>{"motion", "relocalise"}));
  EXPECT_TRUE(tracking_.visual_odometry());
  // The map is found again.
  relocalise_ = true;
  local_map_ = true;
  EXPECT_TRUE(tracking_.Track(Tracked(), Moves(), &frame_));
  EXPECT_FALSE(tracking_.visual_odometry());
  // Back in odometry, then neither motion nor the map: lost.
  relocalise_ = false;
  local_map_ = false;
  ASSERT_TRUE(tracking_.Track(Tracked(), Moves(), &frame_));
  ASSERT_TRUE(tracking_.visual_odometry());
  motion_ = false;
  EXPECT_FALSE(tracking_.Track(Tracked(), Moves(), &frame_));
  EXPECT_FALSE(tracking_.visual_odometry());
}

}  // namespace
}  // namespace pkslam
