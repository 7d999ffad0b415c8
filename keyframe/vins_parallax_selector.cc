#include "keyframe/vins_parallax_selector.h"

#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "keyframe/selector_common.h"

namespace pkslam {

void VinsParallaxOptions::Check() const {
  PKSLAM_CHECK_OPTION(parallax_px > 0 && focal_px > 0, "Keyframe.parallax", "{} px at focal {}",
                      parallax_px, focal_px);
  PKSLAM_CHECK_OPTION(min_tracked >= 0, "Keyframe.min_tracked", "{}", min_tracked);
  PKSLAM_CHECK_OPTION(imu_uninitialised_interval_s > 0, "Keyframe.imu_uninitialised_interval", "{}",
                      imu_uninitialised_interval_s);
}

VinsParallaxSelector::VinsParallaxSelector(VinsParallaxOptions options) : options_(options) {
  options_.Check();
}

void VinsParallaxSelector::Reset() {
  keyframe_.reset();
  previous_.reset();
}

VinsParallaxSelector::View VinsParallaxSelector::MakeView(const SelectorInput& in) {
  View v;
  v.frame = in.frame_id;
  v.world_from_camera = in.camera_from_world.Inverse().so3().Matrix();
  if (in.fx <= 0 || in.fy <= 0) return v;  // no calibration: no features to compare
  for (const SelectorPoint& p : in.points) {
    v.normalised.emplace(p.id,
                         Eigen::Vector2d((p.uv.x() - in.cx) / in.fx, (p.uv.y() - in.cy) / in.fy));
  }
  return v;
}

void VinsParallaxSelector::OnKeyFrameInserted(const SelectorInput& input) {
  keyframe_ = MakeView(input);
  previous_ = keyframe_;
}

SelectorDecision VinsParallaxSelector::Decide(const SelectorInput& in) {
  const View current = MakeView(in);
  struct RememberFrame {
    std::optional<View>* previous;
    const View& current;
    ~RememberFrame() { *previous = current; }
  } remember{&previous_, current};

  if (auto exit = CommonSafetyExits(in, options_.imu_uninitialised_interval_s)) return *exit;
  SelectorTrace trace;
  const int tracked = static_cast<int>(in.points.size());
  trace["tracked"] = tracked;
  bool few = tracked < options_.min_tracked;
  bool parallax_rule = false;
  if (keyframe_ && previous_ && previous_->frame != keyframe_->frame) {
    const bool compensate =
        options_.rotation_compensation && IsInertial(in.sensor) && in.imu_initialized;
    // Rotation taking a bearing in the keyframe's camera into the previous frame's camera.
    const Eigen::Matrix3d previous_from_keyframe =
        previous_->world_from_camera.transpose() * keyframe_->world_from_camera;
    double sum = 0;
    int shared = 0;
    for (const auto& [id, pj] : previous_->normalised) {
      const auto it = keyframe_->normalised.find(id);
      if (it == keyframe_->normalised.end()) continue;
      const Eigen::Vector2d& pi = it->second;
      double parallax = (pi - pj).norm();
      if (compensate) {
        const Eigen::Vector3d rotated = previous_from_keyframe * Eigen::Vector3d(pi.x(), pi.y(), 1);
        if (rotated.z() > 0) {
          parallax = std::min(parallax, (rotated.head<2>() / rotated.z() - pj).norm());
        }
      }
      sum += parallax;
      ++shared;
    }
    trace["shared"] = shared;
    if (shared == 0) {
      few = true;  // VINS-Mono: no feature shared, keyframe
    } else {
      const double mean = sum / shared;
      trace["parallax_px"] = mean * options_.focal_px;  // in VINS-Mono's 460 px units
      parallax_rule = mean >= options_.parallax_px / options_.focal_px;
    }
  }
  ReasonList reasons;
  reasons.Add(parallax_rule, "parallax");
  reasons.Add(few, "few-tracked");
  return DecideFromReasons(in, reasons, std::move(trace));
}

}  // namespace pkslam
