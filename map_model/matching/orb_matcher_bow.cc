// OrbMatcher: searches that pair features by vocabulary node (keyframe-frame and
// keyframe-keyframe BoW search, epipolar search for triangulation) and the window search of
// monocular initialisation.
#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"
#include "map_model/matching/orb_matcher_internal.h"

namespace pkslam {

using matching_detail::BestTwo;
using matching_detail::ForEachCommonNode;
using matching_detail::HasRight;
using matching_detail::kNoDistance;
using matching_detail::RotationHistogram;

namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

Eigen::Matrix3d InverseK(const CameraRig& rig) {
  Eigen::Matrix3d k;
  k << rig.fx, 0, rig.cx, 0, rig.fy, rig.cy, 0, 0, 1;
  return k.inverse();
}

// Fundamental matrix with x1^T * F12 * x2 = 0 for pixels x1 of kf1 and x2 of kf2.
Eigen::Matrix3d FundamentalMatrix12(const KeyFrame& kf1, const KeyFrame& kf2) {
  const SE3d cam1_from_cam2 = kf1.camera_from_world() * kf2.world_from_camera();
  const Eigen::Matrix3d essential =
      Skew(cam1_from_cam2.translation()) * cam1_from_cam2.RotationMatrix();
  return InverseK(kf1.rig()).transpose() * essential * InverseK(kf2.rig());
}

}  // namespace

int OrbMatcher::SearchByBoW(const KeyFrame& keyframe, const Frame& frame,
                            std::vector<MapPointPtr>* matches) const {
  PKSLAM_CHECK(matches != nullptr, "null output");
  PKSLAM_CHECK(frame.HasBoW(), "frame {} has no BoW (call ComputeBoW first)", frame.id());
  matches->assign(static_cast<std::size_t>(frame.size()), nullptr);
  const auto& kf_points = keyframe.map_points();
  const auto& kf_descriptors = keyframe.descriptors();
  const auto& kf_keypoints = keyframe.keypoints_undistorted();
  const auto& descriptors = frame.descriptors();
  const auto& keypoints = frame.keypoints_undistorted();
  RotationHistogram histogram;
  int n = 0;
  ForEachCommonNode(keyframe.feature_vector(), frame.feature_vector(),
                    [&](const std::vector<std::uint32_t>& kf_group,
                        const std::vector<std::uint32_t>& frame_group) {
                      for (const std::uint32_t i_kf : kf_group) {
                        const MapPointPtr& point = kf_points[i_kf];
                        if (!point || point->IsBad()) continue;
                        const Descriptor& d_kf = kf_descriptors[i_kf];
                        BestTwo best;
                        for (const std::uint32_t i_f : frame_group) {
                          if ((*matches)[i_f]) continue;
                          best.Add(HammingDistance(d_kf, descriptors[i_f]), static_cast<int>(i_f),
                                   0);
                        }
                        if (best.best > kOrbThLow) continue;
                        if (!PassesRatio(best.best, best.second)) continue;
                        (*matches)[best.best_index] = point;
                        ++n;
                        if (check_orientation_) {
                          histogram.Add(kf_keypoints[i_kf].angle, keypoints[best.best_index].angle,
                                        best.best_index);
                        }
                      }
                    });
  if (check_orientation_) {
    histogram.RejectInconsistent([&](int idx) {
      (*matches)[idx] = nullptr;
      --n;
    });
  }
  return n;
}

int OrbMatcher::SearchByBoW(const KeyFrame& kf1, const KeyFrame& kf2,
                            std::vector<MapPointPtr>* matches12) const {
  PKSLAM_CHECK(matches12 != nullptr, "null output");
  matches12->assign(static_cast<std::size_t>(kf1.size()), nullptr);
  const auto& points1 = kf1.map_points();
  const auto& points2 = kf2.map_points();
  const auto& descriptors1 = kf1.descriptors();
  const auto& descriptors2 = kf2.descriptors();
  const auto& keypoints1 = kf1.keypoints_undistorted();
  const auto& keypoints2 = kf2.keypoints_undistorted();
  std::vector<std::uint8_t> matched2(static_cast<std::size_t>(kf2.size()), 0);
  RotationHistogram histogram;
  int n = 0;
  ForEachCommonNode(
      kf1.feature_vector(), kf2.feature_vector(),
      [&](const std::vector<std::uint32_t>& group1, const std::vector<std::uint32_t>& group2) {
        for (const std::uint32_t i1 : group1) {
          const MapPointPtr& point1 = points1[i1];
          if (!point1 || point1->IsBad()) continue;
          const Descriptor& d1 = descriptors1[i1];
          BestTwo best;
          for (const std::uint32_t i2 : group2) {
            if (matched2[i2]) continue;
            const MapPointPtr& point2 = points2[i2];
            if (!point2 || point2->IsBad()) continue;
            best.Add(HammingDistance(d1, descriptors2[i2]), static_cast<int>(i2), 0);
          }
          if (best.best >= kOrbThLow) continue;
          if (!PassesRatio(best.best, best.second)) continue;
          (*matches12)[i1] = points2[best.best_index];
          matched2[best.best_index] = 1;
          ++n;
          if (check_orientation_) {
            histogram.Add(keypoints1[i1].angle, keypoints2[best.best_index].angle,
                          static_cast<int>(i1));
          }
        }
      });
  if (check_orientation_) {
    histogram.RejectInconsistent([&](int i1) {
      (*matches12)[i1] = nullptr;
      --n;
    });
  }
  return n;
}

int OrbMatcher::SearchForInitialization(const Frame& f1, const Frame& f2,
                                        std::vector<cv::Point2f>* prev_matched,
                                        std::vector<int>* matches12, int window_size) const {
  PKSLAM_CHECK(prev_matched != nullptr && matches12 != nullptr, "null output");
  PKSLAM_CHECK(static_cast<int>(prev_matched->size()) == f1.size(),
               "{} previous positions for {} keypoints", prev_matched->size(), f1.size());
  const auto& keypoints1 = f1.keypoints_undistorted();
  const auto& keypoints2 = f2.keypoints_undistorted();
  const auto& descriptors1 = f1.descriptors();
  const auto& descriptors2 = f2.descriptors();
  matches12->assign(static_cast<std::size_t>(f1.size()), -1);
  std::vector<int> matches21(static_cast<std::size_t>(f2.size()), -1);
  std::vector<int> distance21(static_cast<std::size_t>(f2.size()), kNoDistance);
  for (int i1 = 0; i1 < f1.size(); ++i1) {
    const int level = keypoints1[i1].octave;
    if (level > 0) continue;
    const cv::Point2f& around = (*prev_matched)[i1];
    const std::vector<int> candidates =
        f2.FeaturesInArea(around.x, around.y, window_size, level, level);
    if (candidates.empty()) continue;
    const Descriptor& d1 = descriptors1[i1];
    BestTwo best;
    for (const int i2 : candidates) {
      const int d = HammingDistance(d1, descriptors2[i2]);
      // A keypoint already claimed more cheaply is no candidate (nor a competitor).
      if (distance21[i2] <= d) continue;
      best.Add(d, i2, 0);
    }
    if (best.best > kOrbThLow) continue;
    if (!PassesRatio(best.best, best.second)) continue;
    const int i2 = best.best_index;
    if (matches21[i2] >= 0) (*matches12)[matches21[i2]] = -1;  // the better claim wins
    (*matches12)[i1] = i2;
    matches21[i2] = i1;
    distance21[i2] = best.best;
  }
  if (check_orientation_) {
    RotationHistogram histogram;
    for (int i1 = 0; i1 < f1.size(); ++i1) {
      const int i2 = (*matches12)[i1];
      if (i2 >= 0) histogram.Add(keypoints1[i1].angle, keypoints2[i2].angle, i1);
    }
    histogram.RejectInconsistent([&](int i1) { (*matches12)[i1] = -1; });
  }
  int n = 0;
  for (int i1 = 0; i1 < f1.size(); ++i1) {
    const int i2 = (*matches12)[i1];
    if (i2 < 0) continue;
    (*prev_matched)[i1] = keypoints2[i2].pt;
    ++n;
  }
  return n;
}

std::vector<std::pair<int, int>> OrbMatcher::SearchForTriangulation(const KeyFrame& kf1,
                                                                    const KeyFrame& kf2,
                                                                    bool only_stereo) const {
  const Eigen::Matrix3d f12 = FundamentalMatrix12(kf1, kf2);
  // Epipole: kf1's centre in kf2's image. Features near it have no usable parallax.
  const CameraRig& rig2 = kf2.rig();
  const Eigen::Vector3d c1_in_2 = kf2.camera_from_world() * kf1.CameraCenter();
  const bool has_epipole = std::abs(c1_in_2.z()) > 1e-9;
  const double ex = has_epipole ? rig2.fx * c1_in_2.x() / c1_in_2.z() + rig2.cx : 0;
  const double ey = has_epipole ? rig2.fy * c1_in_2.y() / c1_in_2.z() + rig2.cy : 0;

  const auto& points1 = kf1.map_points();
  const auto& points2 = kf2.map_points();
  const auto& keypoints1 = kf1.keypoints_undistorted();
  const auto& keypoints2 = kf2.keypoints_undistorted();
  const auto& descriptors1 = kf1.descriptors();
  const auto& descriptors2 = kf2.descriptors();
  const auto& right1 = kf1.right_u();
  const auto& right2 = kf2.right_u();
  const ScalePyramid& pyramid2 = rig2.pyramid;

  std::vector<int> matches12(static_cast<std::size_t>(kf1.size()), -1);
  std::vector<int> matches21(static_cast<std::size_t>(kf2.size()), -1);
  std::vector<int> distance21(static_cast<std::size_t>(kf2.size()), kNoDistance);
  ForEachCommonNode(
      kf1.feature_vector(), kf2.feature_vector(),
      [&](const std::vector<std::uint32_t>& group1, const std::vector<std::uint32_t>& group2) {
        for (const std::uint32_t i1 : group1) {
          if (points1[i1]) continue;
          const bool stereo1 = HasRight(right1, static_cast<int>(i1));
          if (only_stereo && !stereo1) continue;
          const cv::KeyPoint& kp1 = keypoints1[i1];
          // Epipolar line of kp1 in kf2: l = F12^T x1.
          const Eigen::Vector3d line = f12.transpose() * Eigen::Vector3d(kp1.pt.x, kp1.pt.y, 1.0);
          const double line_norm2 = line.x() * line.x() + line.y() * line.y();
          if (line_norm2 <= 0) continue;
          const Descriptor& d1 = descriptors1[i1];
          int best = kOrbThLow;
          int best_index = -1;
          for (const std::uint32_t i2 : group2) {
            if (points2[i2]) continue;
            const bool stereo2 = HasRight(right2, static_cast<int>(i2));
            if (only_stereo && !stereo2) continue;
            const int d = HammingDistance(d1, descriptors2[i2]);
            if (d > best || d >= distance21[i2]) continue;
            const cv::KeyPoint& kp2 = keypoints2[i2];
            const double scale = pyramid2.scale[kp2.octave];
            if (!stereo1 && !stereo2 && has_epipole) {
              const double dx = ex - kp2.pt.x;
              const double dy = ey - kp2.pt.y;
              if (dx * dx + dy * dy < 100.0 * scale * scale) continue;
            }
            const double num = line.x() * kp2.pt.x + line.y() * kp2.pt.y + line.z();
            if (num * num / line_norm2 >= 3.84 * pyramid2.sigma2[kp2.octave]) continue;
            best = d;
            best_index = static_cast<int>(i2);
          }
          if (best_index < 0) continue;
          if (matches21[best_index] >= 0) matches12[matches21[best_index]] = -1;
          matches12[i1] = best_index;
          matches21[best_index] = static_cast<int>(i1);
          distance21[best_index] = best;
        }
      });
  if (check_orientation_) {
    RotationHistogram histogram;
    for (int i1 = 0; i1 < kf1.size(); ++i1) {
      const int i2 = matches12[i1];
      if (i2 >= 0) histogram.Add(keypoints1[i1].angle, keypoints2[i2].angle, i1);
    }
    histogram.RejectInconsistent([&](int i1) { matches12[i1] = -1; });
  }
  std::vector<std::pair<int, int>> pairs;
  for (int i1 = 0; i1 < kf1.size(); ++i1) {
    if (matches12[i1] >= 0) pairs.emplace_back(i1, matches12[i1]);
  }
  return pairs;
}

}  // namespace pkslam
