#include "map_model/estimation/ransac_inputs.h"

#include "core/util/error.h"
#include "map_model/frame.h"
#include "map_model/keyframe.h"
#include "map_model/map_point.h"

namespace pkslam {

std::vector<PnpCorrespondence> MakePnpCorrespondences(const Frame& frame,
                                                      const std::vector<MapPointPtr>& matches) {
  PKSLAM_CHECK(static_cast<int>(matches.size()) == frame.size(),
               "{} matches for frame {} with {} keypoints", matches.size(), frame.id(),
               frame.size());
  const auto& sigma2 = frame.rig().pyramid.sigma2;
  std::vector<PnpCorrespondence> out;
  for (int i = 0; i < frame.size(); ++i) {
    const MapPointPtr& mp = matches[static_cast<std::size_t>(i)];
    if (!mp || mp->IsBad()) continue;
    const cv::KeyPoint& kp = frame.keypoints_undistorted()[static_cast<std::size_t>(i)];
    out.push_back({Eigen::Vector2d(kp.pt.x, kp.pt.y), sigma2[static_cast<std::size_t>(kp.octave)],
                   mp->position(), i});
  }
  return out;
}

PinholeIntrinsics IntrinsicsOf(const KeyFrame& kf) {
  const CameraRig& rig = kf.rig();
  return {rig.fx, rig.fy, rig.cx, rig.cy};
}

std::vector<Sim3Match> MakeSim3Matches(const KeyFrame& kf1, const KeyFrame& kf2,
                                       const std::vector<MapPointPtr>& matches12) {
  PKSLAM_CHECK(static_cast<int>(matches12.size()) == kf1.size(),
               "{} matches for keyframe {} with {} keypoints", matches12.size(), kf1.id(),
               kf1.size());
  const auto& sigma2_1 = kf1.rig().pyramid.sigma2;
  const auto& sigma2_2 = kf2.rig().pyramid.sigma2;
  std::vector<Sim3Match> out;
  for (int i1 = 0; i1 < kf1.size(); ++i1) {
    const MapPointPtr& mp2 = matches12[static_cast<std::size_t>(i1)];
    const MapPointPtr& mp1 = kf1.map_point(i1);
    if (!mp1 || !mp2 || mp1->IsBad() || mp2->IsBad()) continue;
    const int i2 = mp2->IndexInKeyFrame(&kf2);
    if (i2 < 0) continue;
    const cv::KeyPoint& kp1 = kf1.keypoints_undistorted()[static_cast<std::size_t>(i1)];
    const cv::KeyPoint& kp2 = kf2.keypoints_undistorted()[static_cast<std::size_t>(i2)];
    Sim3Match m;
    m.point1 = kf1.camera_from_world() * mp1->position();
    m.point2 = kf2.camera_from_world() * mp2->position();
    m.uv1 = Eigen::Vector2d(kp1.pt.x, kp1.pt.y);
    m.uv2 = Eigen::Vector2d(kp2.pt.x, kp2.pt.y);
    m.sigma2_1 = sigma2_1[static_cast<std::size_t>(kp1.octave)];
    m.sigma2_2 = sigma2_2[static_cast<std::size_t>(kp2.octave)];
    m.index1 = i1;
    m.index2 = i2;
    out.push_back(m);
  }
  return out;
}

}  // namespace pkslam
