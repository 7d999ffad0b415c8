#include "tracking/inertial_pose_optimizer.h"

#include <vector>

#include "core/util/error.h"
#include "map_model/estimation/frame_correspondences.h"

namespace pkslam {

InertialPoseOutput OptimizeInertialPose(Frame* frame, const InertialPoseInput& input,
                                        const PoseOptimizerOptions& options) {
  PKSLAM_CHECK(frame->HasPose(), "frame {} has no initial pose", frame->id());
  const CameraRig& rig = frame->rig();
  const BodyCamera camera = BodyCamera::Of(rig.intrinsics(), rig.body_from_camera.Inverse());
  std::vector<PoseCorrespondence> corrs =
      CollectPoseCorrespondences(*frame, /*depth_information=*/false);
  const NavState initial{frame->camera_from_world().Inverse() * camera.camera_from_body,
                         frame->imu.state.velocity_world};
  const InertialPoseOutput out =
      SolveInertialPose(camera, initial, frame->imu.state.bias, &corrs, input, options);

  WriteOutlierFlags(corrs, frame);
  frame->SetPose((out.state.world_from_body * camera.camera_from_body.Inverse()).Inverse());
  frame->imu.state.velocity_world = out.state.velocity_world;
  frame->imu.state.bias = out.bias;
  frame->imu.state.valid = true;
  return out;
}

}  // namespace pkslam
