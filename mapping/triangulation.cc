#include "mapping/triangulation.h"

#include <Eigen/SVD>
#include <cmath>

#include "map_model/keyframe.h"

namespace pkslam {
namespace {

// chi2 95% thresholds (2 and 3 DoF) on the reprojection error, scaled by sigma^2.
constexpr double kChi2Mono = 5.991;
constexpr double kChi2Stereo = 7.8;

bool ReprojectionOk(const KeyFrame& kf, int index, const Eigen::Vector3d& p_world) {
  const CameraRig& rig = kf.rig();
  const Eigen::Vector3d pc = kf.camera_from_world() * p_world;
  if (pc.z() <= 0) return false;
  const double inv_z = 1.0 / pc.z();
  const cv::KeyPoint& kp = kf.keypoints_undistorted()[index];
  const double sigma2 = rig.pyramid.sigma2[kp.octave];
  const double u = rig.fx * pc.x() * inv_z + rig.cx;
  const double v = rig.fy * pc.y() * inv_z + rig.cy;
  const double ex = u - kp.pt.x;
  const double ey = v - kp.pt.y;
  const float u_right = kf.right_u().empty() ? -1.0f : kf.right_u()[index];
  if (u_right < 0) return ex * ex + ey * ey <= kChi2Mono * sigma2;
  const double disparity_info = kf.DisparityInformation(index);
  if (disparity_info > 0) {
    // RGB-D: the depth reading has its own sigma (estimators/optim/reprojection_error.h).
    const double ed = rig.bf * inv_z - (kp.pt.x - u_right);
    return (ex * ex + ey * ey) / sigma2 + disparity_info * ed * ed <= kChi2Stereo;
  }
  const double er = (u - rig.bf * inv_z) - u_right;
  return ex * ex + ey * ey + er * er <= kChi2Stereo * sigma2;
}

}  // namespace

bool HasTriangulationBaseline(const KeyFrame& kf1, const KeyFrame& kf2, bool monocular) {
  const double baseline = (kf2.CameraCenter() - kf1.CameraCenter()).norm();
  if (!monocular) return baseline >= kf2.rig().baseline;
  const double median_depth = kf2.SceneDepthQuantile(0.5);
  return median_depth > 0 && baseline / median_depth >= 0.01;
}

std::optional<Eigen::Vector3d> TriangulateDlt(const Eigen::Vector2d& xn1,
                                              const Eigen::Vector2d& xn2,
                                              const Eigen::Matrix<double, 3, 4>& p1,
                                              const Eigen::Matrix<double, 3, 4>& p2) {
  Eigen::Matrix4d a;
  a.row(0) = xn1.x() * p1.row(2) - p1.row(0);
  a.row(1) = xn1.y() * p1.row(2) - p1.row(1);
  a.row(2) = xn2.x() * p2.row(2) - p2.row(0);
  a.row(3) = xn2.y() * p2.row(2) - p2.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(a, Eigen::ComputeFullV);
  const Eigen::Vector4d h = svd.matrixV().col(3);
  if (std::abs(h(3)) < 1e-12) return std::nullopt;
  const Eigen::Vector3d p = h.head<3>() / h(3);
  if (!p.allFinite()) return std::nullopt;
  return p;
}

std::optional<Eigen::Vector3d> TriangulatePair(const KeyFrame& kf1, int i1, const KeyFrame& kf2,
                                               int i2, bool monocular) {
  const CameraRig& rig = kf1.rig();
  const cv::KeyPoint& kp1 = kf1.keypoints_undistorted()[i1];
  const cv::KeyPoint& kp2 = kf2.keypoints_undistorted()[i2];
  const bool stereo1 = !kf1.right_u().empty() && kf1.right_u()[i1] >= 0;
  const bool stereo2 = !kf2.right_u().empty() && kf2.right_u()[i2] >= 0;
  const Eigen::Vector2d xn1((kp1.pt.x - rig.cx) * rig.inv_fx, (kp1.pt.y - rig.cy) * rig.inv_fy);
  const Eigen::Vector2d xn2((kp2.pt.x - rig.cx) * rig.inv_fx, (kp2.pt.y - rig.cy) * rig.inv_fy);
  const Eigen::Vector3d ray1 = kf1.world_from_camera().so3() * xn1.homogeneous();
  const Eigen::Vector3d ray2 = kf2.world_from_camera().so3() * xn2.homogeneous();
  const double cos_rays = ray1.dot(ray2) / (ray1.norm() * ray2.norm());

  // Parallax a stereo view gives on its own: the angle the baseline subtends at the depth.
  double cos_stereo1 = 2.0;
  double cos_stereo2 = 2.0;
  if (stereo1) cos_stereo1 = std::cos(2 * std::atan2(rig.baseline / 2, kf1.depth()[i1]));
  if (stereo2) cos_stereo2 = std::cos(2 * std::atan2(rig.baseline / 2, kf2.depth()[i2]));
  const double cos_stereo = std::min(cos_stereo1, cos_stereo2);

  std::optional<Eigen::Vector3d> p;
  const double max_cos = monocular ? 0.9998 : 0.9998;
  if (cos_rays < cos_stereo && cos_rays > 0 && (stereo1 || stereo2 || cos_rays < max_cos)) {
    p = TriangulateDlt(xn1, xn2, kf1.camera_from_world().Matrix3x4(),
                       kf2.camera_from_world().Matrix3x4());
  } else if (stereo1 && cos_stereo1 < cos_stereo2) {
    p = kf1.UnprojectStereo(i1);
  } else if (stereo2 && cos_stereo2 < cos_stereo1) {
    p = kf2.UnprojectStereo(i2);
  }
  if (!p) return std::nullopt;
  if (!ReprojectionOk(kf1, i1, *p) || !ReprojectionOk(kf2, i2, *p)) return std::nullopt;

  // Scale consistency: the distance ratio must agree with the octave ratio.
  const double d1 = (*p - kf1.CameraCenter()).norm();
  const double d2 = (*p - kf2.CameraCenter()).norm();
  if (d1 <= 0 || d2 <= 0) return std::nullopt;
  const double ratio_distance = d2 / d1;
  const double ratio_octave = rig.pyramid.scale[kp1.octave] / rig.pyramid.scale[kp2.octave];
  const double factor = 1.5 * rig.pyramid.scale_factor;
  if (ratio_distance * factor < ratio_octave || ratio_distance > ratio_octave * factor) {
    return std::nullopt;
  }
  return p;
}

}  // namespace pkslam
