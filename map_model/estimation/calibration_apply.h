// Moving the map model to a new calibration estimate (online calibration, docs/calibration.md):
// the Apply phase of the calibration bundle adjustment (Collect: calibration_collect.h).
#pragma once

#include "core/sensor/rig_calibration.h"
#include "estimators/calibration/calibration_bundle.h"
#include "map_model/atlas.h"

namespace pkslam {

class MapWriteLock;

// With the Atlas's write lock (a parameter). Every keyframe of every map (live and retired) moves
// to `setup`, the rig of `result.estimate` (KeyFrame::Recalibrate: keypoints re-rectified or
// re-undistorted, stereo depths recomputed, poses expressed in the new tracking camera with the
// body kept), the Atlas takes the estimate as its calibration, and then the problem's keyframes,
// points, velocities and biases of `map` get the adjustment's values; keyframes and points the
// map gained while it ran follow their parent / reference keyframe (MergeGlobalBundle). Records
// a world change in `map` so tracking predicts from its keyframes again. The adjustment's
// outliers are not erased (local BA decides about observations). `map` may be null (the map
// went away meanwhile): then only the calibration moves.
void ApplyCalibration(const MapWriteLock& lock, Atlas* atlas, Map* map,
                      const CalibrationBundleProblem& problem,
                      const CalibrationBundleResult& result, const RigSetup& setup);

// Every point of map `map_id` refined with the keyframe poses held (structure-only,
// estimators/optim/point_refinement.h), so points the thinned calibration adjustment left out
// move to the new calibration too. Takes the Atlas lock itself: shared to collect and solve,
// exclusive (kCalibration) to write. Returns the points moved.
int RefinePointsToCalibration(Atlas* atlas, MapId map_id);

// Only the calibration: every keyframe moves to `setup` as above, poses and points stay (a
// calibration read from a file or a map, before or between adjustments). With the Atlas's
// write lock (a parameter).
void MoveToCalibration(const MapWriteLock& lock, Atlas* atlas, const RigCalibration& calibration,
                       const RigSetup& setup);

}  // namespace pkslam
