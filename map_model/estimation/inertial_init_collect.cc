#include "map_model/estimation/inertial_init_collect.h"

#include "core/util/error.h"
#include "core/util/log.h"
#include "imu/preintegration.h"
#include "map_model/estimation/inertial_bundle_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/world_transform.h"

namespace pkslam {
namespace {

// `next` follows `previous` in the same map's temporal chain.
bool LinkedAfter(const KeyFrame* previous, const KeyFrame* next) {
  return next != nullptr && !next->IsBad() && next->map() == previous->map() &&
         next->imu().previous() == previous && next->imu().from_previous.has_value();
}

}  // namespace

std::vector<KeyFrame*> InertialChainThrough(KeyFrame* kf) {
  std::vector<KeyFrame*> chain = InertialChain::EndingAt(kf, 0);
  if (chain.empty()) return chain;
  while (LinkedAfter(chain.back(), chain.back()->imu().next()))
    chain.push_back(chain.back()->imu().next());
  return chain;
}

int PropagateVelocities(const MapWriteLock& lock, KeyFrame* last, const ImuBias& bias,
                        const Eigen::Vector3d& gravity_world, double scale) {
  RequireWriteLock(lock, "PropagateVelocities");
  int count = 0;
  for (KeyFrame* previous = last; previous->imu().state.valid; previous = previous->imu().next()) {
    KeyFrame* next = previous->imu().next();
    if (!LinkedAfter(previous, next) || next->imu().state.valid) break;
    const NavState start{previous->world_from_body(), scale * previous->imu().state.velocity_world};
    const NavState predicted = PredictState(start, *next->imu().from_previous, bias, gravity_world);
    InertialState& state = next->mutable_imu(lock).state;
    state.velocity_world = predicted.velocity_world / scale;
    state.valid = true;
    ++count;
  }
  return count;
}

std::optional<InertialInitProblem> CollectInertialInit(KeyFrame* keyframe,
                                                       const InertialInitRule& rule) {
  if (keyframe->IsBad() || keyframe->map() == nullptr) return std::nullopt;
  InertialInitProblem problem;
  problem.chain = InertialChainThrough(keyframe);
  const std::vector<KeyFrame*>& chain = problem.chain;
  if (chain.empty()) return std::nullopt;
  problem.newest = keyframe->map()->Share(chain.back());
  PKSLAM_LOG_DEBUG("IMU initialisation check at kf {}: chain {}", keyframe->id(), chain.size());
  if (static_cast<int>(chain.size()) < rule.min_keyframes) return std::nullopt;
  const double span = static_cast<double>(chain.back()->t_ns() - chain.front()->t_ns()) * 1e-9;
  if (span < rule.min_time_s) return std::nullopt;
  if (rule.min_travel >= 0) {
    double travel = 0;
    for (std::size_t i = 1; i < chain.size(); ++i) {
      travel += (chain[i]->CameraCenter() - chain[i - 1]->CameraCenter()).norm();
    }
    // Scale is unobservable without motion: wait (documented in mapping/inertial_mapping.h).
    PKSLAM_LOG_DEBUG("IMU initialisation check: travel {:.3f}", travel);
    if (travel < rule.min_travel) return std::nullopt;
  }
  for (std::size_t i = 0; i < chain.size(); ++i) {
    problem.keyframes.push_back({chain[i]->t_ns(), chain[i]->world_from_body()});
    if (i > 0) problem.preintegrations.push_back(*chain[i]->imu().from_previous);
  }
  problem.initial_bias = keyframe->imu().state.bias;
  return problem;
}

void ApplyScaledRotation(const MapWriteLock& lock, Map* map, const SO3d& new_from_old,
                         double scale) {
  RequireWriteLock(lock, "ApplyScaledRotation");
  for (const auto& [id, kf] : map->keyframes()) {
    kf->SetPose(lock, CameraFromMovedWorld(kf->camera_from_world(), new_from_old, scale));
    kf->mutable_imu(lock).state.velocity_world =
        VelocityInMovedWorld(kf->imu().state.velocity_world, new_from_old, scale);
  }
  for (const auto& [id, point] : map->map_points()) {
    if (point->IsBad()) continue;
    point->SetPosition(lock, scale * (new_from_old * point->position()));
    point->UpdateNormalAndDepth(lock);
  }
}

void ApplyInertialInit(const MapWriteLock& lock, Map* map, const InertialInitProblem& problem,
                       const InertialInitResult& result, bool refinement, std::int64_t t_ns) {
  RequireWriteLock(lock, "ApplyInertialInit");
  const std::vector<KeyFrame*>& chain = problem.chain;
  PKSLAM_CHECK(result.velocities_world.size() == chain.size(),
               "ApplyInertialInit: {} velocities for {} keyframes", result.velocities_world.size(),
               chain.size());
  const SO3d new_from_old = result.world_from_gravity.Inverse();
  // Chain keyframes get the estimated velocities, keyframes tracking added after them since
  // the collection predicted ones; any other without a state (cut off by an IMU gap) the
  // newest one's. Everything is rotated (and scaled) below.
  for (std::size_t i = 0; i < chain.size(); ++i) {
    if (chain[i]->IsBad()) continue;
    InertialState& state = chain[i]->mutable_imu(lock).state;
    state.velocity_world = result.velocities_world[i];
    state.valid = true;
  }
  for (const auto& [id, other] : map->keyframes()) {
    KeyFrameImu& imu = other->mutable_imu(lock);
    imu.state.bias = result.bias;
    if (imu.from_previous) Reintegrate(result.bias, &*imu.from_previous);
  }
  PropagateVelocities(lock, chain.back(), result.bias, result.gravity_world, result.scale);
  for (const auto& [id, other] : map->keyframes()) {
    if (!other->imu().state.valid) {
      InertialState& state = other->mutable_imu(lock).state;
      state.velocity_world = result.velocities_world.back();
      state.valid = true;
    }
  }
  ApplyScaledRotation(lock, map, new_from_old, result.scale);
  map->mutable_imu_status(lock).imu_initialized = true;
  if (!refinement) map->mutable_imu_status(lock).imu_init_t_ns = t_ns;
  map->RecordWorldChange(lock, {WorldChange::Kind::kTransform, new_from_old, result.scale});
}

}  // namespace pkslam
