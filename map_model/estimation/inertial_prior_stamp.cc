#include "map_model/estimation/inertial_prior_stamp.h"

#include "map_model/map.h"

namespace pkslam {

void StampPrior(const Map& map, InertialStatePrior* prior) {
  prior->map_id = map.id();
  prior->map_change_index = map.change_index();
  prior->world_transforms = map.NumWorldTransforms();
}

bool PriorIsValid(const InertialStatePrior& prior, const Map& map) {
  return prior.map_id == map.id() && prior.map_change_index == map.change_index() &&
         prior.world_transforms == map.NumWorldTransforms();
}

}  // namespace pkslam
