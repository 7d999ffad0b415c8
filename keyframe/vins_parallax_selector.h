// "vins-parallax": VINS-Mono's keyframe rule (FeatureManager::addFeatureCheckParallax). VINS
// keeps the second-latest frame of its window as a keyframe when the features it shares with the
// third-latest (the last kept frame) moved on average by at least MIN_PARALLAX = 10 px at a
// virtual focal length of 460 px, i.e. 10 / 460 in focal-normalised image units, or when fewer
// than 20 features of the newest frame were tracked from earlier frames (or none are shared).
// The per-feature parallax is the smaller of the raw displacement and the displacement after
// rotating the older bearing into the newer camera (rotation compensation; VINS-Mono's release
// has that line commented out, pkslam uses the estimated rotations when the IMU is initialised).
// pkslam decides for the current frame, so the keyframe it inserts is the frame after the one
// VINS would keep (one frame later); behind ORB-SLAM3's common safety exits.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <unordered_map>

#include "keyframe/keyframe_selector.h"

namespace pkslam {

struct VinsParallaxOptions {
  double parallax_px = 10.0;  // MIN_PARALLAX in pixels at focal_px
  double focal_px = 460.0;    // VINS-Mono's FOCAL_LENGTH: the threshold is parallax_px / focal_px
  int min_tracked = 20;       // fewer tracked features in the newest frame: keyframe
  bool rotation_compensation = true;  // inertial sensors with an initialised IMU
  double imu_uninitialised_interval_s = 0.25;

  void Check() const;
};

class VinsParallaxSelector : public KeyframeSelector {
 public:
  explicit VinsParallaxSelector(VinsParallaxOptions options);
  std::string_view name() const override { return "vins-parallax"; }
  bool NeedsTrackedPoints() const override { return true; }
  SelectorDecision Decide(const SelectorInput& input) override;
  void OnKeyFrameInserted(const SelectorInput& input) override;
  void Reset() override;

 private:
  // A frame's tracked features: focal-normalised image coordinates per map point, and the
  // frame's camera orientation.
  struct View {
    FrameId frame = 0;
    Eigen::Matrix3d world_from_camera = Eigen::Matrix3d::Identity();
    std::unordered_map<MapPointId, Eigen::Vector2d> normalised;
  };
  static View MakeView(const SelectorInput& input);

  VinsParallaxOptions options_;
  std::optional<View> keyframe_;  // the third-latest frame's role: the last kept frame
  std::optional<View> previous_;  // the second-latest frame
};

}  // namespace pkslam
