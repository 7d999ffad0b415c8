#include "map_model/inertial_chain.h"

#include <fmt/format.h>

#include <algorithm>

#include "core/util/error.h"
#include "imu/preintegration.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"

namespace pkslam {
namespace {


}  // namespace

void InertialChain::Append(const MapWriteLock& lock, KeyFrame* previous, KeyFrame* keyframe,
                           std::optional<PreintegratedImu> from_previous) const {
  RequireWriteLock(lock, "InertialChain::Append");
  PKSLAM_CHECK(previous != nullptr && keyframe != nullptr && previous != keyframe,
               "InertialChain::Append needs two keyframes");
  PKSLAM_CHECK(previous->map() == map_ && keyframe->map() == map_,
               "InertialChain::Append: keyframes {} and {} are not both of map {}", previous->id(),
               keyframe->id(), map_->id());
  keyframe->imu_.previous_ = previous;
  previous->imu_.next_ = keyframe;
  keyframe->imu_.from_previous = std::move(from_previous);
}

void InertialChain::SpliceOut(const MapWriteLock& lock, KeyFrame* keyframe) const {
  RequireWriteLock(lock, "InertialChain::SpliceOut");
  KeyFrame* previous = keyframe->imu_.previous_;
  KeyFrame* next = keyframe->imu_.next_;
  if (next != nullptr && next->imu_.previous_ == keyframe) {
    if (previous != nullptr && keyframe->imu_.from_previous && next->imu_.from_previous) {
      // The merged interval starts at `previous`: linearise it at that keyframe's bias.
      PreintegratedImu& merged = *next->imu_.from_previous;
      merged.bias = previous->imu_.state.bias;
      MergePrevious(*keyframe->imu_.from_previous, &merged);
      next->imu_.previous_ = previous;
      previous->imu_.next_ = next;
    } else {
      next->imu_.previous_ = nullptr;
      next->imu_.from_previous.reset();
      if (previous != nullptr && previous->imu_.next_ == keyframe) previous->imu_.next_ = nullptr;
    }
  } else if (previous != nullptr && previous->imu_.next_ == keyframe) {
    previous->imu_.next_ = nullptr;
  }
  keyframe->imu_.previous_ = nullptr;
  keyframe->imu_.next_ = nullptr;
  keyframe->imu_.from_previous.reset();
  keyframe->imu_.prior.reset();
}

std::vector<KeyFrame*> InertialChain::EndingAt(KeyFrame* newest, int max_length) {
  std::vector<KeyFrame*> chain;
  if (newest == nullptr || newest->IsBad()) return chain;
  chain.push_back(newest);
  KeyFrame* k = newest;
  while ((max_length <= 0 || static_cast<int>(chain.size()) < max_length) &&
         k->imu_.previous_ != nullptr && k->imu_.from_previous && !k->imu_.previous_->IsBad() &&
         k->imu_.previous_->map() == newest->map()) {
    k = k->imu_.previous_;
    chain.push_back(k);
  }
  std::reverse(chain.begin(), chain.end());
  return chain;
}

void InertialChain::Restore(KeyFrame* keyframe, KeyFrame* previous, KeyFrame* next) {
  keyframe->imu_.previous_ = previous;
  keyframe->imu_.next_ = next;
}

std::optional<std::string> InertialChain::Check() const {
  auto check = [&](const KeyFrame& k) -> std::optional<std::string> {
    const KeyFrame* previous = k.imu_.previous_;
    const KeyFrame* next = k.imu_.next_;
    if (previous != nullptr) {
      if (previous->imu_.next_ != &k) {
        return fmt::format("keyframe {}: its previous {} does not link back", k.id(),
                           previous->id());
      }
      if (previous->map() != k.map()) {
        return fmt::format("keyframe {}: its previous {} is in another map", k.id(),
                           previous->id());
      }
    }
    if (next != nullptr && next->imu_.previous_ != &k) {
      return fmt::format("keyframe {}: its next {} does not link back", k.id(), next->id());
    }
    return std::nullopt;
  };
  for (const auto* keyframes : {&map_->keyframes(), &map_->retired_keyframes()}) {
    for (const auto& [id, k] : *keyframes) {
      if (auto problem = check(*k)) return problem;
    }
  }
  return std::nullopt;
}

}  // namespace pkslam
