#include "tracking/pose_optimizer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "core/util/error.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

using testing::FrameOptions;
using testing::MakeFrame;
using testing::MakeScene;
using testing::MakeStereoRig;

constexpr double kDeg = M_PI / 180.0;

struct PoseScene {
  std::shared_ptr<CameraRig> rig = MakeStereoRig();
  testing::SyntheticScene scene = MakeScene(600, 3);
  SE3d truth =
      SE3d::Exp((Eigen::Matrix<double, 6, 1>() << 0.2, -0.1, 0.3, 0.02, -0.05, 0.01).finished());
  std::vector<int> point_of_keypoint;

  // A frame matched to map points at their true positions, posed at a perturbation of the
  // truth: 10 cm translation and 3 degrees of rotation.
  Frame MakeMatchedFrame(const FrameOptions& options) {
    Frame frame = MakeFrame(scene, rig, truth, 1, 0, options, &point_of_keypoint);
    for (int i = 0; i < frame.size(); ++i) {
      frame.map_points[i] =
          std::make_shared<MapPoint>(i, scene.points_world[point_of_keypoint[i]], nullptr, nullptr);
    }
    frame.SetPose(Perturbed());
    return frame;
  }
  SE3d Perturbed() const {
    Eigen::Matrix<double, 6, 1> delta;
    delta.head<3>() = Eigen::Vector3d(1, -2, 1.5).normalized() * 0.10;
    delta.tail<3>() = Eigen::Vector3d(-1, 1, 2).normalized() * 3.0 * kDeg;
    return SE3d::Exp(delta) * truth;
  }
  double TranslationError(const Frame& f) const {
    return (f.CameraCenter() - truth.Inverse().translation()).norm();
  }
  double RotationErrorDeg(const Frame& f) const {
    return (f.camera_from_world().so3() * truth.so3().Inverse()).Angle() / kDeg;
  }
  // Distance (pixels) between a keypoint and the true projection of its point.
  double ProjectionError(const Frame& f, int i) const {
    const auto uv = rig->camera.Project(truth * scene.points_world[point_of_keypoint[i]]);
    const cv::Point2f& p = f.keypoints_undistorted()[i].pt;
    return (*uv - Eigen::Vector2d(p.x, p.y)).norm();
  }
};

FrameOptions Options(bool stereo, double noise = 0.0, double outliers = 0.0) {
  FrameOptions o;
  o.stereo = stereo;
  o.pixel_noise = noise;
  o.outlier_fraction = outliers;
  o.seed = 7;
  return o;
}

TEST(PoseOptimizer, StereoConvergesFromPerturbedPose) {
  PoseScene s;
  Frame frame = s.MakeMatchedFrame(Options(true));
  ASSERT_GT(frame.size(), 300);
  ASSERT_GT(s.TranslationError(frame), 0.09);
  const int inliers = OptimizePose(&frame);
  EXPECT_EQ(inliers, frame.size());
  EXPECT_LT(s.TranslationError(frame), 1e-3);
  EXPECT_LT(s.RotationErrorDeg(frame), 0.05);
  for (int i = 0; i < frame.size(); ++i) EXPECT_EQ(frame.outliers[i], 0) << i;
}

TEST(PoseOptimizer, MonocularConvergesFromPerturbedPose) {
  PoseScene s;
  Frame frame = s.MakeMatchedFrame(Options(false));
  ASSERT_TRUE(frame.right_u().empty());
  const int inliers = OptimizePose(&frame);
  EXPECT_EQ(inliers, frame.size());
  EXPECT_LT(s.TranslationError(frame), 1e-3);
  EXPECT_LT(s.RotationErrorDeg(frame), 0.05);
}

// Moved keypoints (>= 10 px from their true projection) must be flagged; keypoints within
// noise must not. Half a pixel of noise keeps genuine chi2 values far below the thresholds.
void CheckOutlierClassification(bool stereo) {
  PoseScene s;
  Frame frame = s.MakeMatchedFrame(Options(stereo, 0.5, 0.15));
  // Stale flags from an earlier call must not survive.
  std::fill(frame.outliers.begin(), frame.outliers.end(), 1);
  const int inliers = OptimizePose(&frame);
  int moved = 0, flagged = 0;
  for (int i = 0; i < frame.size(); ++i) {
    const double e = s.ProjectionError(frame, i);
    flagged += frame.outliers[i];
    if (e > 10.0) {
      ++moved;
      EXPECT_EQ(frame.outliers[i], 1) << i << " error " << e;
    } else if (e < 3.0) {
      EXPECT_EQ(frame.outliers[i], 0) << i << " error " << e;
    }
  }
  EXPECT_GT(moved, frame.size() / 10);
  EXPECT_EQ(inliers, frame.size() - flagged);
  EXPECT_LT(s.TranslationError(frame), 0.01);
  EXPECT_LT(s.RotationErrorDeg(frame), 0.2);
}

TEST(PoseOptimizer, StereoOutliersAreFlagged) { CheckOutlierClassification(true); }
TEST(PoseOptimizer, MonocularOutliersAreFlagged) { CheckOutlierClassification(false); }

// A frame with stereo and monocular keypoints (right_u < 0 for some) uses both residual kinds:
// with only the keypoints lacking right_u moved, they are the ones flagged.
TEST(PoseOptimizer, MixedStereoAndMonocularKeypoints) {
  PoseScene s;
  Frame source = s.MakeMatchedFrame(Options(true));
  FrameFeatures f;
  f.keypoints = source.keypoints();
  f.descriptors = source.descriptors();
  f.right_u = source.right_u();
  f.depth = source.depth();
  std::vector<int> moved;
  for (int i = 0; i < static_cast<int>(f.keypoints.size()); ++i) {
    if (i % 3 == 0) {
      f.right_u[i] = -1.0f;
      f.depth[i] = -1.0f;
      if (i % 30 == 0) {
        f.keypoints[i].pt.x += 25.0f;
        moved.push_back(i);
      }
    }
  }
  Frame frame(2, 0, s.rig, std::move(f));
  frame.map_points = source.map_points;
  frame.SetPose(s.Perturbed());
  const int inliers = OptimizePose(&frame);
  EXPECT_EQ(inliers, frame.size() - static_cast<int>(moved.size()));
  for (int i : moved) EXPECT_EQ(frame.outliers[i], 1) << i;
  EXPECT_LT(s.TranslationError(frame), 1e-3);
  EXPECT_LT(s.RotationErrorDeg(frame), 0.05);
}

TEST(PoseOptimizer, FewerThanThreeCorrespondencesLeavesThePose) {
  PoseScene s;
  Frame frame = s.MakeMatchedFrame(Options(true));
  for (int i = 2; i < frame.size(); ++i) frame.map_points[i] = nullptr;
  const SE3d before = frame.camera_from_world();
  EXPECT_EQ(OptimizePose(&frame), 0);
  EXPECT_EQ(frame.camera_from_world().Matrix(), before.Matrix());
}

TEST(PoseOptimizer, PointsBehindTheCameraAreOutliers) {
  PoseScene s;
  Frame frame = s.MakeMatchedFrame(Options(true));
  // Mirror a few points through the camera centre: behind the camera, in line with the pixel.
  const SE3d world_from_camera = s.truth.Inverse();
  for (int i : {5, 17, 42}) {
    const Eigen::Vector3d p_camera = s.truth * frame.map_points[i]->position();
    // A point of no map (the scene's points have none), so no map lock to move it: a new one.
    frame.map_points[i] =
        std::make_shared<MapPoint>(i, world_from_camera * (-p_camera), nullptr, nullptr);
  }
  const int inliers = OptimizePose(&frame);
  EXPECT_EQ(inliers, frame.size() - 3);
  for (int i : {5, 17, 42}) EXPECT_EQ(frame.outliers[i], 1);
  EXPECT_LT(s.TranslationError(frame), 1e-3);
}

TEST(PoseOptimizer, SingleThreadedIsBitIdentical) {
  PoseScene s;
  Frame a = s.MakeMatchedFrame(Options(true, 1.0, 0.1));
  Frame b = s.MakeMatchedFrame(Options(true, 1.0, 0.1));
  const int inliers_a = OptimizePose(&a);
  const int inliers_b = OptimizePose(&b);
  EXPECT_EQ(inliers_a, inliers_b);
  EXPECT_EQ(a.outliers, b.outliers);
  const Eigen::Matrix4d ma = a.camera_from_world().Matrix();
  const Eigen::Matrix4d mb = b.camera_from_world().Matrix();
  EXPECT_EQ(std::memcmp(ma.data(), mb.data(), sizeof(double) * 16), 0);
  // Across processes: compare this between two runs with --gtest_output=xml.
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a
  const auto* bytes = reinterpret_cast<const unsigned char*>(ma.data());
  for (std::size_t i = 0; i < sizeof(double) * 16; ++i) hash = (hash ^ bytes[i]) * 1099511628211ull;
  RecordProperty("pose_fnv1a", std::to_string(hash));
}

TEST(PoseOptimizer, RejectsBadOptionsAndMissingPose) {
  PoseScene s;
  Frame frame = s.MakeMatchedFrame(Options(true));
  PoseOptimizerOptions o;
  o.rounds = 0;
  EXPECT_THROW(OptimizePose(&frame, o), OptionError);
  Frame unposed = MakeFrame(s.scene, s.rig, s.truth, 3, 0, Options(true), &s.point_of_keypoint);
  EXPECT_THROW(OptimizePose(&unposed), Error);
}

}  // namespace
}  // namespace pkslam
