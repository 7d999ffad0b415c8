#include "mapping/inertial_init_chain.h"

#include "imu/preintegration.h"
#include "map_model/estimation/inertial_bundle_collect.h"
#include "map_model/keyframe.h"

namespace pkslam {
namespace {

// `next` follows `previous` in the same map's temporal chain.
bool LinkedAfter(const KeyFrame* previous, const KeyFrame* next) {
  return next != nullptr && !next->IsBad() && next->map() == previous->map() &&
         next->imu.previous() == previous && next->imu.from_previous.has_value();
}

}  // namespace

std::vector<KeyFrame*> InertialChainThrough(KeyFrame* kf) {
  std::vector<KeyFrame*> chain = InertialChain::EndingAt(kf, 0);
  if (chain.empty()) return chain;
  while (LinkedAfter(chain.back(), chain.back()->imu.next()))
    chain.push_back(chain.back()->imu.next());
  return chain;
}

int PropagateVelocities(KeyFrame* last, const ImuBias& bias, const Eigen::Vector3d& gravity_world,
                        double scale) {
  int count = 0;
  for (KeyFrame* previous = last; previous->imu.state.valid; previous = previous->imu.next()) {
    KeyFrame* next = previous->imu.next();
    if (!LinkedAfter(previous, next) || next->imu.state.valid) break;
    const NavState start{previous->world_from_body(), scale * previous->imu.state.velocity_world};
    const NavState predicted = PredictState(start, *next->imu.from_previous, bias, gravity_world);
    next->imu.state.velocity_world = predicted.velocity_world / scale;
    next->imu.state.valid = true;
    ++count;
  }
  return count;
}

}  // namespace pkslam
