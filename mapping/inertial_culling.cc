#include "mapping/inertial_culling.h"

#include "core/util/error.h"
#include "imu/preintegration.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"

namespace pkslam {
namespace {

double SecondsBetween(const KeyFrame& a, const KeyFrame& b) {
  return static_cast<double>(b.t_ns() - a.t_ns()) * 1e-9;
}

Eigen::Vector3d BodyPosition(const KeyFrame& kf) { return kf.world_from_body().translation(); }

}  // namespace

void InertialCullingOptions::Check() const {
  PKSLAM_CHECK_OPTION(redundancy_stereo > 0 && redundancy_stereo <= 1 && redundancy_mono > 0 &&
                          redundancy_mono <= 1,
                      "inertial.culling_redundancy", "{} / {}", redundancy_stereo, redundancy_mono);
  PKSLAM_CHECK_OPTION(window >= 2, "inertial.culling_window", "{}", window);
  PKSLAM_CHECK_OPTION(max_gap_recent_s > 0 && max_gap_old_s >= max_gap_recent_s,
                      "inertial.culling_max_gap", "{} / {}", max_gap_recent_s, max_gap_old_s);
  PKSLAM_CHECK_OPTION(still_distance >= 0, "inertial.culling_still_distance", "{}", still_distance);
}

InertialCullingContext MakeInertialCullingContext(const KeyFrame& current,
                                                  const InertialCullingOptions& options) {
  InertialCullingContext c;
  c.current_id = current.id();
  const KeyFrame* k = &current;
  for (int n = 1; n < options.window && k->imu().previous() != nullptr; ++n)
    k = k->imu().previous();
  c.window_start_id = k->id();
  if (const Map* map = current.map()) {
    c.map_keyframes = map->NumKeyFrames();
    c.imu_initialized = map->imu_status().imu_initialized;
    c.refined = map->imu_status().inertial_ba2_done;
  }
  return c;
}

bool InertialCullingAllowed(const KeyFrame& candidate, const InertialCullingContext& context,
                            const InertialCullingOptions& options) {
  if (!options.enabled || context.map_keyframes <= options.window) return false;
  if (candidate.id() + 2 > context.current_id) return false;  // the two newest stay
  const KeyFrame* previous = candidate.imu().previous();
  const KeyFrame* next = candidate.imu().next();
  if (previous == nullptr || next == nullptr || previous->IsBad() || next->IsBad() ||
      !candidate.imu().from_previous || !next->imu().from_previous ||
      next->imu().previous() != &candidate) {
    return false;
  }
  const double gap = SecondsBetween(*previous, *next);
  if (gap < options.max_gap_recent_s) return true;
  if (gap >= options.max_gap_old_s) return false;
  if (context.imu_initialized && candidate.id() < context.window_start_id) return true;
  return !context.refined &&
         (BodyPosition(candidate) - BodyPosition(*previous)).norm() < options.still_distance;
}

int RepairInertialChain(const MapWriteLock& lock, KeyFrame* newest, int length) {
  int spliced = 0;
  KeyFrame* k = newest;
  for (int n = 0; n < length && k != nullptr; ++n) {
    KeyFrame* previous = k->imu().previous();
    while (previous != nullptr && previous->IsBad()) {
      previous->map()->inertial_chain().SpliceOut(lock, previous);
      ++spliced;
      previous = k->imu().previous();
    }
    k = previous;
  }
  return spliced;
}

}  // namespace pkslam
