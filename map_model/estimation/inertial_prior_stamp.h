// The map side of the local inertial BA's marginalisation prior
// (estimators/inertial/marginalization.h): a prior is stamped with the map it was computed in
// and used only while that map has not moved as a whole.
#pragma once

#include "core/imu/inertial_state.h"
#include "estimators/inertial/marginalization.h"

namespace pkslam {

class Map;

// Records `map`'s identity and change indices in `prior`. Requires the Atlas mutex.
void StampPrior(const Map& map, InertialStatePrior* prior);

// Whether `prior` may still be used in `map` (same map, no map-wide change since). Requires the
// Atlas mutex.
bool PriorIsValid(const InertialStatePrior& prior, const Map& map);

}  // namespace pkslam
