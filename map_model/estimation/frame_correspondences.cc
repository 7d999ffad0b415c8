#include "map_model/estimation/frame_correspondences.h"

#include "core/util/error.h"
#include "map_model/map_point.h"

namespace pkslam {

std::vector<PoseCorrespondence> CollectPoseCorrespondences(const Frame& frame,
                                                           bool depth_information) {
  const CameraRig& rig = frame.rig();
  const int n = frame.size();
  PKSLAM_CHECK(static_cast<int>(frame.map_points.size()) == n,
               "{} map-point slots for {} keypoints", frame.map_points.size(), n);
  const auto& keypoints = frame.keypoints_undistorted();
  const auto& right_u = frame.right_u();
  const auto& inv_sigma2 = rig.pyramid.inv_sigma2;
  std::vector<PoseCorrespondence> out;
  out.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const MapPointPtr& point = frame.map_points[i];
    if (!point) continue;
    const cv::KeyPoint& kp = keypoints[i];
    PKSLAM_CHECK(kp.octave >= 0 && kp.octave < static_cast<int>(inv_sigma2.size()),
                 "keypoint {} has octave {}", i, kp.octave);
    PoseCorrespondence& c = out.emplace_back();
    c.keypoint = i;
    c.stereo = !right_u.empty() && right_u[i] >= 0;
    c.p_world = point->position();
    c.obs = Eigen::Vector3d(kp.pt.x, kp.pt.y, c.stereo ? right_u[i] : -1.0);
    c.inv_sigma2 = inv_sigma2[kp.octave];
    if (c.stereo && depth_information) c.disparity_inv_sigma2 = frame.DisparityInformation(i);
  }
  return out;
}

int WriteOutlierFlags(const std::vector<PoseCorrespondence>& correspondences, Frame* frame) {
  frame->outliers.assign(static_cast<std::size_t>(frame->size()), 0);
  int outliers = 0;
  for (const PoseCorrespondence& c : correspondences) {
    const bool outlier = c.block == nullptr;
    frame->outliers[c.keypoint] = outlier ? 1 : 0;
    outliers += outlier ? 1 : 0;
  }
  return outliers;
}

}  // namespace pkslam
