// Test helper: synthetic keyframes joined into an inertial chain.
#pragma once

#include <vector>

#include "imu/preintegration.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"

namespace pkslam::testing {

// Appends consecutive `keyframes` to their map's inertial chain, each with its preintegration of
// `samples` from its predecessor, linearised at `bias`.
inline void LinkWithImu(const MapWriteLock& lock, const std::vector<KeyFramePtr>& keyframes,
                        const std::vector<ImuMeasurement>& samples, const ImuBias& bias,
                        const ImuNoise& noise) {
  for (std::size_t k = 1; k < keyframes.size(); ++k) {
    KeyFrame* kf = keyframes[k].get();
    KeyFrame* previous = keyframes[k - 1].get();
    PreintegratedImu pim = StartPreintegration(bias, noise);
    IntegrateSamples(samples, previous->t_ns(), kf->t_ns(), &pim);
    kf->map()->inertial_chain().Append(lock, previous, kf, pim);
  }
}

}  // namespace pkslam::testing
