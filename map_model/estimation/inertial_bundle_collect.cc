// Collect and Apply phases of visual-inertial bundle adjustment; the solver is
// estimators/inertial/inertial_bundle_solve.cc.
#include "map_model/estimation/inertial_bundle_collect.h"

#include <algorithm>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "core/util/error.h"
#include "estimators/inertial/gravity_gauge.h"
#include "imu/preintegration.h"
#include "map_model/estimation/inertial_prior_stamp.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"

namespace pkslam {
namespace {

// Inertial role of a problem keyframe (InertialBundleProblem::inertial).
constexpr std::uint8_t kNoInertial = 0;
constexpr std::uint8_t kFreeInertial = 1;
constexpr std::uint8_t kFixedInertial = 2;

PreintegratedImu WithoutSteps(const PreintegratedImu& pim) {
  PreintegratedImu p = pim;
  p.steps.clear();
  p.steps.shrink_to_fit();
  return p;
}

void AddKeyFrame(KeyFrame* kf, bool fixed, std::uint8_t inertial, InertialBundleProblem* problem,
                 BundleKeyFrameIndex* index) {
  PKSLAM_CHECK(kf->map() != nullptr && kf->map()->Share(kf) != nullptr,
               "keyframe {} is not live in its map", kf->id());
  (*index)[kf] = static_cast<int>(problem->visual.keyframes.size());
  problem->visual.keyframes.push_back({kf->id(), kf->camera_from_world(), fixed});
  problem->inertial.push_back(inertial);
  problem->velocities.push_back(kf->imu().state.velocity_world);
  problem->biases.push_back(kf->imu().state.bias);
}

void SetCommon(const KeyFrame& kf, const InertialBundleOptions& options,
               InertialBundleProblem* problem) {
  const CameraRig& rig = kf.rig();
  problem->visual.fx = rig.fx;
  problem->visual.fy = rig.fy;
  problem->visual.cx = rig.cx;
  problem->visual.cy = rig.cy;
  problem->visual.bf = rig.bf;
  problem->visual.map_id = kf.map() != nullptr ? kf.map()->id() : kInvalidId;
  problem->camera_from_body = rig.body_from_camera.Inverse();
  problem->gravity_world = Eigen::Vector3d(0, 0, -options.gravity_magnitude);
}

void AddEdges(const std::vector<KeyFrame*>& chain, const BundleKeyFrameIndex& index,
              InertialBundleProblem* problem) {
  for (std::size_t i = 1; i < chain.size(); ++i) {
    problem->edges.push_back(
        {index.at(chain[i - 1]), index.at(chain[i]), WithoutSteps(*chain[i]->imu().from_previous)});
  }
}

std::vector<MapPointPtr> PointsOf(const std::vector<KeyFrame*>& keyframes, const Map* map) {
  std::vector<MapPointPtr> points;
  std::unordered_set<const MapPoint*> seen;
  for (const KeyFrame* kf : keyframes) {
    for (const MapPointPtr& point : kf->map_points()) {
      if (point && !point->IsBad() && point->map() == map && seen.insert(point.get()).second) {
        points.push_back(point);
      }
    }
  }
  return points;
}

}  // namespace

InertialBundleProblem CollectLocalInertialBundle(KeyFrame* keyframe,
                                                 const InertialBundleOptions& options) {
  options.Check();
  InertialBundleProblem problem;
  std::vector<KeyFrame*> chain = InertialChain::EndingAt(keyframe, options.window + 1);
  // Only keyframes with an estimated inertial state take part (they all have one once the
  // map's IMU is initialised, except possibly the newest few).
  while (!chain.empty() && !chain.front()->imu().state.valid) chain.erase(chain.begin());
  if (chain.size() < 2) return problem;
  for (std::size_t i = 1; i < chain.size(); ++i) {
    if (!chain[i]->imu().state.valid) {
      chain.resize(i);
      break;
    }
  }
  if (chain.size() < 2) return problem;
  const Map* map = keyframe->map();
  SetCommon(*keyframe, options, &problem);
  BundleKeyFrameIndex index;
  // The oldest is the anchor, joined by its inertial edge: free with its marginalisation prior
  // when it has a valid one, otherwise fixed.
  const KeyFrame* anchor = chain.front();
  const bool with_prior = options.marginalization_prior && anchor->imu().prior &&
                          PriorIsValid(*anchor->imu().prior, *map);
  for (std::size_t i = 0; i < chain.size(); ++i) {
    const bool fixed = i == 0 && !with_prior;
    AddKeyFrame(chain[i], fixed, fixed ? kFixedInertial : kFreeInertial, &problem, &index);
  }
  AddEdges(chain, index, &problem);
  if (options.marginalization_prior) {
    if (with_prior) problem.anchor_prior = *anchor->imu().prior;
    problem.marginalize_from = 0;
    problem.marginalize_to = 1;
    StampPrior(*map, &problem.stamps);
  }
  const std::vector<KeyFrame*> free(chain.begin() + 1, chain.end());
  const std::vector<MapPointPtr> points = PointsOf(free, map);
  // Fixed visual keyframes: other observers of the points, those sharing most first.
  std::unordered_map<KeyFrame*, int> shared;
  for (const MapPointPtr& point : points) {
    for (const auto& [id, obs] : point->observations()) {
      if (index.count(obs.keyframe) > 0 || obs.keyframe->IsBad() || obs.keyframe->map() != map) {
        continue;
      }
      ++shared[obs.keyframe];
    }
  }
  std::vector<std::pair<int, KeyFrame*>> ranked;
  for (const auto& [kf, count] : shared) ranked.emplace_back(count, kf);
  std::sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second->id() < b.second->id();
  });
  if (static_cast<int>(ranked.size()) > options.max_fixed_keyframes) {
    ranked.resize(static_cast<std::size_t>(options.max_fixed_keyframes));
  }
  for (const auto& [count, kf] : ranked) AddKeyFrame(kf, true, kNoInertial, &problem, &index);
  for (const MapPointPtr& point : points) AddBundlePoint(point, index, &problem.visual);
  return problem;
}

InertialBundleProblem CollectFullInertialBundle(KeyFrame* newest,
                                                const InertialBundleOptions& options,
                                                bool free_tilt, double gauge_information) {
  options.Check();
  InertialBundleProblem problem;
  const std::vector<KeyFrame*> chain = InertialChain::EndingAt(newest, 0);
  if (chain.size() < 2) return problem;
  const Map* map = newest->map();
  SetCommon(*newest, options, &problem);
  BundleKeyFrameIndex index;
  // The first pose anchors position and yaw (fixed, or with free_tilt by a prior on just those);
  // its velocity and biases stay free.
  for (std::size_t i = 0; i < chain.size(); ++i) {
    AddKeyFrame(chain[i], i == 0 && !free_tilt, kFreeInertial, &problem, &index);
  }
  AddEdges(chain, index, &problem);
  if (free_tilt) {
    const KeyFrame& first = *chain.front();
    problem.anchor_prior =
        PositionYawPrior({first.world_from_body(), first.imu().state.velocity_world},
                         first.imu().state.bias, gauge_information);
    problem.marginalize_from = 0;
    problem.marginalize_to = -1;
  }
  std::vector<KeyFrame*> others;
  for (const auto& [id, kf] : map->keyframes()) {
    if (!kf->IsBad() && index.count(kf.get()) == 0) others.push_back(kf.get());
  }
  // Fixed keyframes would hold the world's tilt.
  for (KeyFrame* kf : others) AddKeyFrame(kf, !free_tilt, kNoInertial, &problem, &index);
  for (const MapPointPtr& point : PointsOf(chain, map))
    AddBundlePoint(point, index, &problem.visual);
  return problem;
}

void ApplyInertialBundle(const MapWriteLock& lock, Map* map, const InertialBundleProblem& problem,
                         const InertialBundleResult& result) {
  RequireWriteLock(lock, "ApplyInertialBundle");
  PKSLAM_CHECK(result.velocities.size() == problem.visual.keyframes.size() &&
                   result.biases.size() == problem.visual.keyframes.size(),
               "inertial result does not match the problem");
  ApplyBundle(lock, map, problem.visual, result.visual);
  // The problem's keyframes as they are in the map now (null: moved to another map).
  auto keyframe = [&](int i) {
    return map->KeyFrameById(problem.visual.keyframes[static_cast<std::size_t>(i)].keyframe_id)
        .get();
  };
  for (std::size_t i = 0; i < problem.visual.keyframes.size(); ++i) {
    KeyFrame* kf = keyframe(static_cast<int>(i));
    if (problem.inertial[i] != kFreeInertial || kf == nullptr || kf->IsBad()) continue;
    InertialState& state = kf->mutable_imu(lock).state;
    state.velocity_world = result.velocities[i];
    state.bias = result.biases[i];
    state.valid = true;
  }
  if (result.next_prior && problem.marginalize_to >= 0) {
    KeyFrame* next = keyframe(problem.marginalize_to);
    if (next != nullptr && !next->IsBad() && next->map() != nullptr &&
        PriorIsValid(problem.stamps, *next->map())) {
      std::optional<InertialStatePrior>& prior = next->mutable_imu(lock).prior;
      prior = *result.next_prior;
      StampPrior(*next->map(), &*prior);
    }
  }
  // Preintegrations follow their start keyframe's bias (re-integrated when it moved far).
  const PreintegrationOptions reintegration;
  for (const auto& edge : problem.edges) {
    KeyFrame* from = keyframe(edge.from);
    KeyFrame* to = keyframe(edge.to);
    if (from == nullptr || to == nullptr || from->IsBad() || to->IsBad() ||
        !to->imu().from_previous || to->imu().previous() != from)
      continue;
    UpdateBias(from->imu().state.bias, reintegration, &*to->mutable_imu(lock).from_previous);
  }
}

int StartMissingInertialStates(const MapWriteLock& lock, KeyFrame* newest) {
  RequireWriteLock(lock, "StartMissingInertialStates");
  std::vector<KeyFrame*> missing;
  for (KeyFrame* k = newest; k != nullptr && !k->imu().state.valid; k = k->imu().previous()) {
    missing.push_back(k);
  }
  int started = 0;
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    KeyFrame* k = *it;
    if (k->imu().previous() == nullptr || !k->imu().previous()->imu().state.valid) break;
    k->mutable_imu(lock).state = k->imu().previous()->imu().state;
    ++started;
  }
  return started;
}

void ApplyFullInertialBundle(const MapWriteLock& lock, Map* map, const KeyFrame& newest,
                             const InertialBundleProblem& problem,
                             const InertialBundleResult& result) {
  ApplyInertialBundle(lock, map, problem, result);
  Map* own = newest.map();
  if (own == nullptr) return;
  if (!result.biases.empty()) {
    for (const auto& [id, other] : own->keyframes()) {
      if (other->id() > newest.id()) other->mutable_imu(lock).state.bias = result.biases.front();
    }
  }
  own->RecordWorldChange(lock, {});
  own->IncreaseChangeIndex(lock);
}

}  // namespace pkslam
