// Test helper of the mapping tests: synthetic keyframes joined into an inertial chain.
#pragma once

#include <vector>

#include "imu/preintegration.h"
#include "map_model/keyframe.h"

namespace pkslam::testing {

// Links consecutive `keyframes` (imu.previous / imu.next) and gives each its preintegration of
// `samples` from its predecessor, linearised at `bias`. The Atlas mutex is held (exclusive).
inline void LinkWithImu(const std::vector<KeyFramePtr>& keyframes,
                        const std::vector<ImuMeasurement>& samples, const ImuBias& bias,
                        const ImuNoise& noise) {
  for (std::size_t k = 1; k < keyframes.size(); ++k) {
    KeyFrame* kf = keyframes[k].get();
    KeyFrame* previous = keyframes[k - 1].get();
    kf->imu.previous = previous;
    previous->imu.next = kf;
    PreintegratedImu pim = StartPreintegration(bias, noise);
    IntegrateSamples(samples, previous->t_ns(), kf->t_ns(), &pim);
    kf->imu.from_previous = pim;
  }
}

}  // namespace pkslam::testing
