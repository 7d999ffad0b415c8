// PKS, the photogrammetric keyframe selector (../shared/docs/PKS.md): camera criterion =
// cone-region changes above an adaptive threshold (Eq. 1-9) AND a balanced distribution of
// effective points (ECOG > |COG|, Eq. 10-12); an IMU criterion on sharp acceleration changes;
// combined with ORB-SLAM3's safety exits. This file is "pks", the paper. Deliberate readings
// (docs/keyframe_selectors.md): each point's surface normal is estimated once, when the
// keyframe is taken, from its 5 nearest tracked points, and reused for the current frame, so a
// region change measures the change of viewing direction and not the noise of a re-estimated
// normal; the normal is an unoriented axis (angles in [0, 90]); effective points changed their
// viewing angle by more than delta; the IMU trigger compares the gravity-compensated mean
// specific force (world frame) of the current frame interval with that of the keyframe's
// interval. The authors' released code is "pks-released" (pks_released_selector.h).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <unordered_map>
#include <vector>

#include "keyframe/keyframe_selector.h"
#include "keyframe/pks_math.h"
#include "keyframe/selector_common.h"

namespace pkslam {

struct PksOptions {
  // Width of one cone region (degrees) and number of regions.
  double region_width_deg = 10.0;
  int regions = 4;
  // Viewing-angle change (degrees) that makes a point "effective" for ECOG.
  double delta_deg = 30.0;
  // ECOG grid is grid x grid cells over the image.
  int grid = 3;
  // Neighbours used for a point's surface normal.
  int normal_neighbours = 5;
  // IMU trigger: |delta a| above this (m/s^2); <= 0 disables it.
  double imu_threshold = 1.0;
  // Safety exits and extra triggers kept from ORB-SLAM3 (PKS.md "How it combines").
  double min_translation_m = 0.02;  // no keyframe if the camera moved less (> 2 KFs)
  double imu_uninitialised_interval_s = 0.25;
  double inertial_interval_s = 0.5;  // c1
  // Visual-only sensors (not evaluated in the paper): ORB-SLAM3's c1a, a keyframe at least
  // every this many seconds (its maxFrames = fps), so monocular maps are not starved.
  double visual_interval_s = 1.0;
  int close_tracked_max = 100;  // c3: stereo close-point rule
  int close_untracked_min = 70;
  // Visual-only sensors (not evaluated by the paper): also insert when inliers fall below this
  // share of the reference keyframe's tracked points (ORB-SLAM3's c1c); 0 disables.
  double weak_tracking_ratio = 0.25;
  // pks-released only (pks_released_selector.h); the ablations switch its parts off.
  int forced_interval = 6;          // forced keyframe at exactly this many frames (0: never)
  int late_denominator_after = 4;   // ECOG denominator switch after this many frames
  double pairing_radius_px = 10.0;  // reprojection pairing: search window half-width
  int pairing_max_hamming = 30;     // reprojection pairing: descriptor distance below this
  bool identity_pairing = false;    // ablation: pair by map-point identity instead
  bool frozen_normals = false;      // ablation: keep the keyframe's normals for the frame
  // The released code takes no keyframe while local mapping initialises the IMU (as ORB-SLAM3
  // v0.3); false: such a keyframe waits in the queue as with ORB-SLAM3 v1.0's rule.
  bool no_keyframe_while_imu_initialises = true;

  void Check() const;
};

// The rules PKS combines with its camera and IMU criteria (PKS.md "How it combines"): the
// stereo close-point rule (the released code: only with local mapping idle), the keyframe
// timer (inertial: inertial_interval; visual-only sensors, which the paper did not evaluate:
// visual_interval), weak mono-inertial tracking and, for visual-only sensors, ORB-SLAM3's
// weak-tracking rule.
struct PksCompanionRules {
  bool close = false;
  bool time = false;
  bool weak_mono_inertial = false;
  bool weak = false;
};
PksCompanionRules EvaluatePksCompanionRules(const SelectorInput& input, const PksOptions& options,
                                            bool close_needs_idle_mapping);
// The rules that fired, in PKS's order: camera, forced (pks-released), imu, then the companions.
ReasonList PksReasons(bool camera, bool forced, bool imu, const PksCompanionRules& rules);

class PksSelector : public KeyframeSelector {
 public:
  explicit PksSelector(PksOptions options);
  std::string_view name() const override { return "pks"; }
  bool NeedsTrackedPoints() const override { return true; }
  SelectorDecision Decide(const SelectorInput& input) override;
  void OnKeyFrameInserted(const SelectorInput& input) override;
  void Reset() override;

 private:
  // A point's surface normal in the keyframe's camera frame: a world change (IMU
  // initialisation, scale and gravity refinement, loop correction) moves the keyframe and the
  // point together, so the normal follows them; the keyframe's viewing angle is evaluated at
  // measurement time from the current estimates.
  struct SnapshotPoint {
    Eigen::Vector3d normal_keyframe;
  };
  using Counts = pks::Counts;
  // `diagnostics` (optional) collects each matched point's view change and parallax.
  Counts Measure(const SelectorInput& input, pks::ViewChangeDiagnostics* diagnostics) const;
  // Adds the last keyframe's points that the snapshot does not hold yet (created with the
  // keyframe or triangulated from it afterwards): their normals from the current tracked
  // points.
  void ExtendSnapshot(const SelectorInput& input);
  bool CameraCriterion(const SelectorInput& input, SelectorTrace* trace);
  std::optional<double> AccelerationChange(const SelectorInput& input) const;

  PksOptions options_;
  // Snapshot of the last keyframe (map point id -> normal).
  std::unordered_map<MapPointId, SnapshotPoint> snapshot_;
  bool has_snapshot_ = false;
  // The keyframe interval's gravity-free specific force, in the keyframe's camera frame (so
  // that a world change rotates it along).
  std::optional<Eigen::Vector3d> keyframe_accel_camera_;
  std::optional<Counts> reference_;
};

}  // namespace pkslam
