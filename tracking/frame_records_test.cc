// What tracking keeps of its frames: the inliers a record lists, and how records follow a new
// calibration, a rescaled map and a reset, on keyframes of two synthetic maps.
#include "tracking/frame_records.h"

#include <gtest/gtest.h>

#include "map_model/atlas.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

SE3d Pose(double yaw, double x, double y, double z) {
  return SE3d(SO3d::Exp(Eigen::Vector3d(0.1, -0.05, yaw)), Eigen::Vector3d(x, y, z));
}

class FrameRecordsTest : public ::testing::Test {
 protected:
  FrameRecordsTest()
      : rig_(testing::MakeStereoRig()),
        scene_(testing::MakeScene(300, 4)),
        poses_(testing::MakeForwardPath(3, 0.1, 4)) {
    map_a_ = testing::MakeMap(&atlas_, scene_, rig_, poses_, {});
    {
      auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
      atlas_.CreateNewMap(lock);
    }
    map_b_ = testing::MakeMap(&atlas_, scene_, rig_, poses_, {});
  }

  // Two records on map A's keyframe 1 (one with an online pose), one on map B's.
  void AddRecords() {
    FrameRecord r;
    r.reference = map_a_.keyframes[1];
    r.camera_from_reference = Pose(0.2, 0.3, -0.1, 0.05);
    r.camera_from_world_online = Pose(-0.3, 1.0, 2.0, 3.0);
    records_.Add(r);
    r.camera_from_world_online.reset();
    records_.Add(r);
    r.reference = map_b_.keyframes[1];
    records_.Add(r);
  }

  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticScene scene_;
  std::vector<SE3d> poses_;
  testing::SyntheticMap map_a_;
  testing::SyntheticMap map_b_;
  FrameRecords records_;
};

TEST_F(FrameRecordsTest, InliersAreTheMatchedKeypointsThatAreNotOutliers) {
  std::vector<int> point_of_keypoint;
  Frame frame = testing::MakeFrame(scene_, rig_, poses_[0], 7, 0, {}, &point_of_keypoint);
  frame.map_points.assign(frame.size(), nullptr);
  frame.outliers.assign(frame.size(), 0);
  ASSERT_GT(frame.size(), 12);
  frame.map_points[3] = map_a_.point_of_scene_index[point_of_keypoint[3]];
  frame.map_points[5] = map_a_.point_of_scene_index[point_of_keypoint[5]];
  frame.map_points[9] = map_a_.point_of_scene_index[point_of_keypoint[9]];
  ASSERT_TRUE(frame.map_points[3] && frame.map_points[5] && frame.map_points[9]);
  frame.outliers[5] = 1;
  frame.outliers[11] = 1;  // an outlier without a point

  const auto inliers = InlierObservations(frame);
  ASSERT_EQ(inliers.size(), 2u);
  EXPECT_EQ(inliers[0].point, frame.map_points[3]->id());
  EXPECT_EQ(inliers[1].point, frame.map_points[9]->id());
  EXPECT_EQ(inliers[1].u, frame.keypoints_undistorted()[9].pt.x);
  EXPECT_EQ(inliers[1].v, frame.keypoints_undistorted()[9].pt.y);
}

TEST_F(FrameRecordsTest, ANewCalibrationKeepsEveryBodyWhereItWas) {
  AddRecords();
  const SE3d body_from_camera_old = Pose(0.4, 0.02, -0.01, 0.03);
  const SE3d body_from_camera_new = Pose(0.41, 0.021, -0.012, 0.031);
  const SE3d new_from_old = body_from_camera_new.Inverse() * body_from_camera_old;
  const auto body_motion = [](const FrameRecord& r, const SE3d& body_from_camera) {
    return body_from_camera * r.camera_from_reference * body_from_camera.Inverse();
  };
  const auto world_from_body = [](const FrameRecord& r, const SE3d& body_from_camera) {
    return r.camera_from_world_online->Inverse() * body_from_camera.Inverse();
  };
  const FrameRecord before = records_.all()[0];
  records_.MoveCamera(new_from_old);
  const FrameRecord& after = records_.all()[0];

  EXPECT_GT((after.camera_from_reference.translation() - before.camera_from_reference.translation())
                .norm(),
            1e-4)
      << "the camera moved in the body";
  const SE3d motion_before = body_motion(before, body_from_camera_old);
  const SE3d motion_after = body_motion(after, body_from_camera_new);
  EXPECT_LT((motion_before.translation() - motion_after.translation()).norm(), 1e-12);
  EXPECT_LT((motion_before.so3().Inverse() * motion_after.so3()).Log().norm(), 1e-12);
  const SE3d body_before = world_from_body(before, body_from_camera_old);
  const SE3d body_after = world_from_body(after, body_from_camera_new);
  EXPECT_LT((body_before.translation() - body_after.translation()).norm(), 1e-12);
  EXPECT_LT((body_before.so3().Inverse() * body_after.so3()).Log().norm(), 1e-12);
  EXPECT_FALSE(records_.all()[1].camera_from_world_online) << "no online pose is invented";
}

TEST_F(FrameRecordsTest, ARescaleAndAResetTouchOnlyTheirMap) {
  AddRecords();
  const FrameRecord a = records_.all()[0];
  const FrameRecord b = records_.all()[2];
  records_.Rescale(map_a_.keyframes[1]->map(), 2.5);
  EXPECT_LT((records_.all()[0].camera_from_reference.translation() -
             2.5 * a.camera_from_reference.translation())
                .norm(),
            1e-12);
  EXPECT_LT(
      (records_.all()[0].camera_from_reference.so3().Inverse() * a.camera_from_reference.so3())
          .Log()
          .norm(),
      1e-15)
      << "a rescale turns nothing";
  EXPECT_EQ(records_.all()[2].camera_from_reference.translation(),
            b.camera_from_reference.translation());

  records_.Forget(map_b_.keyframes[1]->map());
  EXPECT_EQ(records_.all()[0].reference, map_a_.keyframes[1]);
  EXPECT_EQ(records_.all()[1].reference, map_a_.keyframes[1]);
  EXPECT_EQ(records_.all()[2].reference, nullptr);
}

TEST_F(FrameRecordsTest, ARecordHoldsThePoseRelativeToItsReferenceAndAKeyframesOwnPose) {
  const KeyFramePtr& reference = map_a_.keyframes[1];
  const SE3d tracked = Pose(0.05, 0.1, 0.0, 0.4);
  // A frame at `t_ns` tracked at `tracked`, one keypoint matched.
  const auto tracked_frame = [&](std::int64_t t_ns) {
    std::vector<int> point_of_keypoint;
    Frame f = testing::MakeFrame(scene_, rig_, poses_[2], 8, t_ns, {}, &point_of_keypoint);
    f.SetPose(tracked);
    f.map_points.assign(f.size(), nullptr);
    f.outliers.assign(f.size(), 0);
    f.map_points[0] = map_a_.point_of_scene_index[point_of_keypoint[0]];
    return f;
  };
  Frame frame = tracked_frame(reference->t_ns() + 1);
  auto lock = MapReader(atlas_).Lock();
  FrameRecord plain;
  records_.SetPose(reference, /*keyframe=*/true, &frame, &plain);
  EXPECT_TRUE(plain.camera_from_reference.Log().isApprox(
      (tracked * reference->world_from_camera()).Log(), 1e-12))
      << "a keyframe made at another time does not move the frame";
  EXPECT_EQ(plain.reference, reference);
  EXPECT_TRUE(plain.observations.empty()) << "observations only when enabled";

  Frame image = tracked_frame(reference->t_ns());
  records_.EnableObservations(true);
  FrameRecord own;
  records_.SetPose(reference, /*keyframe=*/true, &image, &own);
  ASSERT_TRUE(own.camera_from_world_online.has_value());
  EXPECT_TRUE(own.camera_from_world_online->Log().isApprox(tracked.Log(), 1e-12))
      << "the online pose is the tracked one";
  EXPECT_TRUE(own.camera_from_reference.Log().isZero(1e-12)) << "the keyframe's image";
  EXPECT_TRUE(
      image.camera_from_world().Log().isApprox(reference->camera_from_world().Log(), 1e-12));
  EXPECT_EQ(own.observations.size(), 1u);
}

}  // namespace
}  // namespace pkslam
