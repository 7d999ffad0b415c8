// LocalMapper's IMU initialisation when tracking is ahead of local mapping (threaded runs):
// keyframes tracking created after the one that triggers the initialisation are already in the
// map, linked by IMU, and waiting in the queue. Their estimated velocities are what tracking
// predicts the next frames from, so they must be estimated, not guessed.
#include <gtest/gtest.h>

#include <cmath>
#include <mutex>
#include <shared_mutex>
#include <vector>

#include "imu/imu_test_utils.h"
#include "imu/preintegration.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/testing/imu_chain.h"
#include "map_model/testing/synthetic_map.h"
#include "mapping/local_mapper.h"

namespace pkslam {
namespace {

using testing::HelixMotion;

constexpr std::int64_t kImuPeriodNs = 5'000'000;
constexpr std::int64_t kKeyFramePeriodNs = 50'000'000;  // MakeMap's frame spacing

struct InitialisedStates {
  bool initialized = false;
  KeyFrameId trigger = kInvalidId;
  // Per keyframe (in creation order): body-frame velocity estimate (valid state only).
  std::vector<std::optional<Eigen::Vector3d>> body_velocity;
};

// A stereo-inertial map of `num_keyframes` keyframes at their true poses on the helix (camera =
// body), exact IMU (constant gyro bias), all queued at once: local mapping processes them in
// order, and the IMU initialisation (10 keyframes, 0.4 s) fires while the newer ones still wait.
// Returns the keyframe states right after the stage that initialised the IMU.
InitialisedStates RunInitialisationWithQueuedKeyFrames(int num_keyframes,
                                                       std::vector<NavState>* truth) {
  Atlas atlas;
  auto rig = testing::MakeStereoRig(Sensor::kStereoInertial);
  rig->imu = ImuNoise();
  const HelixMotion motion;
  std::vector<SE3d> camera_from_world;
  for (int k = 0; k < num_keyframes; ++k) {
    truth->push_back(motion.State(testing::Seconds(k * kKeyFramePeriodNs)));
    camera_from_world.push_back(truth->back().world_from_body.Inverse());
  }
  // Points on a shell around the helix: every viewing direction sees some.
  testing::SyntheticScene scene = testing::MakeScene(4000, 7);
  std::mt19937 rng(11);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> radius(7.0, 10.0);
  for (Eigen::Vector3d& p : scene.points_world) {
    const Eigen::Vector3d direction = Eigen::Vector3d(n01(rng), n01(rng), n01(rng)).normalized();
    p = radius(rng) * direction;
  }
  const testing::SyntheticMap map =
      testing::MakeMap(&atlas, scene, rig, camera_from_world, testing::FrameOptions());
  const ImuBias bias(Eigen::Vector3d(0.003, -0.002, 0.001), Eigen::Vector3d::Zero());
  const std::vector<ImuMeasurement> samples = SampleImu(
      motion, 0, (num_keyframes - 1) * kKeyFramePeriodNs, kImuPeriodNs, bias, *rig->imu, nullptr);
  {
    auto lock = MapEditor(&atlas).Write(MapEdit::kFixture);
    testing::LinkWithImu(lock, map.keyframes, samples, ImuBias(), *rig->imu);
  }

  LocalMappingOptions options;
  options.cull_keyframes = false;
  options.inertial.min_keyframes = 10;
  options.inertial.min_time_stereo_s = 0.4;
  LocalMapper mapper(&atlas, rig, options);
  InitialisedStates out;
  mapper.SetKeyFrameConsumer([&](const KeyFramePtr& kf) {
    auto lock = MapReader(atlas).Lock();
    if (out.initialized || !kf->map()->imu_status().imu_initialized) return;
    out.initialized = true;
    out.trigger = kf->id();
    for (const KeyFramePtr& k : map.keyframes) {
      if (!k->imu().state.valid) {
        out.body_velocity.emplace_back();
        continue;
      }
      const SO3d world_from_body =
          k->world_from_camera().so3() * rig->body_from_camera.so3().Inverse();
      out.body_velocity.emplace_back(world_from_body.Inverse() * k->imu().state.velocity_world);
    }
  });
  for (const KeyFramePtr& kf : map.keyframes) mapper.InsertKeyFrame(kf);
  mapper.WaitUntilIdle();  // not started: processes the queue here, in order
  return out;
}

TEST(LocalMapperInertial, KeyFramesQueuedAtInitialisationGetEstimatedVelocities) {
  std::vector<NavState> truth;
  const int num_keyframes = 16;
  const InitialisedStates states = RunInitialisationWithQueuedKeyFrames(num_keyframes, &truth);
  ASSERT_TRUE(states.initialized);
  // The initialisation fired before the last keyframes were processed (they were queued).
  ASSERT_LT(states.trigger, num_keyframes - 3);
  ASSERT_EQ(static_cast<int>(states.body_velocity.size()), num_keyframes);
  double worst = 0;
  for (int k = 0; k < num_keyframes; ++k) {
    // Tracking predicts from the newest keyframe: every keyframe of the map must carry a state
    // close to the truth (the body moves ~1.6 m/s and accelerates ~1.4 m/s^2: a copy of an
    // older keyframe's velocity is tenths of m/s off).
    ASSERT_TRUE(states.body_velocity[k].has_value()) << "keyframe " << k;
    const Eigen::Vector3d truth_body =
        truth[k].world_from_body.so3().Inverse() * truth[k].velocity_world;
    const double error = (*states.body_velocity[k] - truth_body).norm();
    worst = std::max(worst, error);
    EXPECT_LT(error, 0.05) << "keyframe " << k << " (initialisation at keyframe " << states.trigger
                           << "): velocity " << states.body_velocity[k]->transpose() << " truth "
                           << truth_body.transpose();
  }
  ::testing::Test::RecordProperty("worst_velocity_error_mps", std::to_string(worst));
}

}  // namespace
}  // namespace pkslam
