#include "tracking/pose_optimizer.h"

#include <vector>

#include "core/util/error.h"
#include "map_model/estimation/frame_correspondences.h"

namespace pkslam {

int OptimizePose(Frame* frame, const PoseOptimizerOptions& options) {
  options.Check();
  PKSLAM_CHECK(frame->HasPose(), "frame {} has no initial pose", frame->id());
  const CameraRig& rig = frame->rig();
  std::vector<PoseCorrespondence> corrs =
      CollectPoseCorrespondences(*frame, /*depth_information=*/true);
  const int num_correspondences = static_cast<int>(corrs.size());
  if (num_correspondences < 3) return 0;
  const SE3d camera_from_world =
      SolvePose(rig.intrinsics(), frame->camera_from_world(), &corrs, options);
  const int num_outliers = WriteOutlierFlags(corrs, frame);
  frame->SetPose(camera_from_world);
  return num_correspondences - num_outliers;
}

}  // namespace pkslam
