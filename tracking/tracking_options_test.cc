// Tracking's options: their check, and the two rules they carry (which lost maps are kept, how
// wide the local map is searched).
#include "tracking/tracking_options.h"

#include <gtest/gtest.h>

#include <string>

#include "core/util/error.h"

namespace pkslam {
namespace {

TEST(TrackingOptions, CheckNamesTheBadOption) {
  EXPECT_NO_THROW(TrackingOptions().Check());
  TrackingOptions bad;
  bad.min_inliers = 0;
  try {
    bad.Check();
    FAIL() << "min_inliers 0 accepted";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("Tracking.min_inliers"), std::string::npos) << e.what();
  }
  bad = TrackingOptions();
  bad.starving_ratio = 1.0;
  EXPECT_THROW(bad.Check(), OptionError);
  bad = TrackingOptions();
  bad.min_two_view_map_points = 0;
  EXPECT_THROW(bad.Check(), OptionError);
  bad = TrackingOptions();
  bad.pose.rounds = 0;
  EXPECT_THROW(bad.Check(), OptionError) << "the pose optimiser's options are checked too";
}

TEST(TrackingOptions, OnlySmallMonocularMapsAreDroppedWhenLost) {
  TrackingOptions options;
  options.min_keyframes_to_keep_map = 7;
  EXPECT_EQ(options.MinKeyFramesToKeepMap(/*monocular=*/true), 7);
  EXPECT_EQ(options.MinKeyFramesToKeepMap(/*monocular=*/false), 0);
}

TEST(TrackingOptions, TheLocalMapSearchWidensAfterRelocalisationAndWhileLost) {
  TrackingOptions options;
  options.local_map_radius = 1.5;
  options.local_map_radius_after_reloc = 6.0;
  EXPECT_EQ(options.LocalSearchRadius(false, false, false), 1.5);
  EXPECT_EQ(options.LocalSearchRadius(true, false, false), 3.0) << "RGB-D";
  EXPECT_EQ(options.LocalSearchRadius(true, true, false), 6.0);
  EXPECT_EQ(options.LocalSearchRadius(false, true, true), 15.0) << "lost wins";
}

TEST(TrackingOptions, OrbSlam3sInertialSearchWidensTheLocalMapAndTheStereoMotionModel) {
  EXPECT_EQ(TrackingOptions::InertialLocalSearchRadius(false, false), 10.0) << "IMU uninitialised";
  EXPECT_EQ(TrackingOptions::InertialLocalSearchRadius(true, false), 6.0) << "before BA2";
  EXPECT_EQ(TrackingOptions::InertialLocalSearchRadius(true, true), 2.0) << "after BA2";
  TrackingOptions options;
  EXPECT_EQ(options.MotionModelRadius(/*monocular=*/false, /*inertial=*/true), 7.0);
  EXPECT_EQ(options.MotionModelRadius(true, true), 15.0);
  options.inertial_search = TrackingOptions::InertialSearch::kOrbSlam3;
  EXPECT_EQ(options.MotionModelRadius(false, true), 15.0) << "ORB-SLAM3: 7 px for STEREO only";
  EXPECT_EQ(options.MotionModelRadius(false, false), 7.0);
}

}  // namespace
}  // namespace pkslam
