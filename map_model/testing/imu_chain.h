// Test helper: synthetic keyframes joined into an inertial chain.
#pragma once

#include <memory>
#include <vector>

#include "imu/imu_test_utils.h"
#include "imu/preintegration.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/testing/synthetic_map.h"

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

// A map of `n` keyframes every 50 ms (MakeMap's spacing) at the true poses of the helix (camera
// = body; the rig's IMU noise model is set to the default), over MakeScene(300, 5), linked by
// exact IMU preintegrations at `bias`; no inertial states yet. Returns the true states.
inline std::vector<NavState> MakeHelixChain(Atlas* atlas, const std::shared_ptr<CameraRig>& rig,
                                            const HelixMotion& motion, int n, const ImuBias& bias,
                                            SyntheticMap* map) {
  rig->imu = ImuNoise();
  std::vector<NavState> truth;
  std::vector<SE3d> camera_from_world;
  for (int k = 0; k < n; ++k) {
    truth.push_back(motion.State(0.05 * k));
    camera_from_world.push_back(truth.back().world_from_body.Inverse());
  }
  *map = MakeMap(atlas, MakeScene(300, 5), rig, camera_from_world, FrameOptions());
  const auto samples =
      SampleImu(motion, 0, (n - 1) * 50'000'000LL, 5'000'000, bias, *rig->imu, nullptr);
  auto lock = MapEditor(atlas).Write(MapEdit::kFixture);
  LinkWithImu(lock, map->keyframes, samples, bias, *rig->imu);
  return truth;
}

}  // namespace pkslam::testing
