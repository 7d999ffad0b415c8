// "pks-released": PKS as the authors' released code runs it (their patched ORB-SLAM3 v0.3,
// Tracking::NeedNewKeyFrame / VisibilityMatrixCondition; ../shared/docs/PKS.md "code:").
// Read point by point against that code; what differs from the paper selector (pks_selector.h):
//  - Snapshot: taken from the frame as the new keyframe holds it, after the new stereo/RGB-D
//    close points were created and with the pose optimisation's outliers still in
//    (SnapshotAfterCreation, NeedsOutliers): per point its position, the map point's
//    descriptor, its surface normal, viewing angle and cone region.
//  - Pairing: each snapshot point is projected into the frame; among the frame's features with
//    a map point inside a +-10 px window the one with the smallest Hamming distance of map-point
//    descriptors pairs with it if that distance is below 30 (several snapshot points may pair
//    with one feature). M counts the pairs, A every map point of the frame (outliers too).
//  - Normals: re-estimated every frame from the frame's points (raw cross-product sum, world
//    z >= 0 reflection, angles in [0, 180]); effective = region changed AND angle changed by more
//    than delta; ECOG bins the paired map point projected into the frame over the undistorted
//    image bounds, strictly (a point on a cell border counts nowhere).
//  - Control flow: a keyframe at exactly `forced_interval` frames; no camera decision when D or
//    M is 0 (before the reference is taken, so an earlier interval's reference survives); the
//    reference is the frame with frames == 1; criterion 1 needs frames > 1; ECOG's late
//    denominator after `late_denominator_after` frames; gamma and the theta < 0.1 clamp.
//  - Exits: no keyframe while local mapping initialises the IMU, nor on the frame after local
//    mapping raised its slow-motion flag (ORB-SLAM3 v0.3's mbBadImu2); the close-point rule
//    needs local mapping idle; the IMU rule compares consecutive frame intervals' mean
//    body-frame acceleration with gravity, after frame 1.
// Ablations (PksOptions): identity_pairing, frozen_normals, forced_interval = 0 (no forced
// keyframe), imu_threshold = 0 (no IMU rule); no_keyframe_while_imu_initialises = false takes
// ORB-SLAM3 v1.0's reading of that exit (in threaded pkslam runs the v0.3 exit starves tracking
// through a slow inertial refinement and loses it: docs/keyframe_selectors.md).
// Remaining differences, documented in docs/keyframe_selectors.md: the released code keeps its
// snapshot and reference in function statics that no map reset clears (here: Reset()); it
// removes duplicate points by equal position (here: by map-point id); equal descriptor
// distances pair with the candidate first in its feature-grid order (here: lowest keypoint
// index); the slow-motion flag is consumed by the next frame's decision even when an earlier
// exit ends it.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "keyframe/keyframe_selector.h"
#include "keyframe/pks_math.h"
#include "keyframe/pks_selector.h"

namespace pkslam {

class PksReleasedSelector : public KeyframeSelector {
 public:
  explicit PksReleasedSelector(PksOptions options);
  std::string_view name() const override { return "pks-released"; }
  bool NeedsTrackedPoints() const override { return true; }
  bool NeedsOutliers() const override { return true; }
  bool SnapshotAfterCreation() const override { return true; }
  SelectorDecision Decide(const SelectorInput& input) override;
  void OnKeyFrameInserted(const SelectorInput& input) override;
  void Reset() override;

 private:
  // One frame's map points, each once (the first keypoint observing it), with the released
  // code's normals, viewing angles and cone regions from that frame's camera centre.
  struct View {
    std::vector<std::size_t> point;  // index into SelectorInput::points
    std::vector<Eigen::Vector3d> normal;
    std::vector<double> angle_deg;
    std::vector<int> region;
  };
  struct SnapshotPoint {
    MapPointId id;
    Eigen::Vector3d position;
    Descriptor descriptor;
    Eigen::Vector3d normal;
    double angle_deg;
    int region;
  };
  using Counts = pks::Counts;
  View MakeView(const SelectorInput& input, bool with_normals) const;
  // Pairs the snapshot with the frame and counts A, M, D and the effective-point grid.
  Counts Measure(const SelectorInput& input, pks::ViewChangeDiagnostics* diagnostics) const;
  bool CameraCriterion(const SelectorInput& input, SelectorTrace* trace);

  PksOptions options_;
  std::vector<SnapshotPoint> snapshot_;
  std::optional<Counts> reference_;                // survives keyframes, as in the released code
  std::optional<Eigen::Vector3d> previous_accel_;  // the previous frame interval's mean
};

}  // namespace pkslam
