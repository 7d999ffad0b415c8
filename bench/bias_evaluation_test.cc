#include "bench/bias_evaluation.h"

#include <gtest/gtest.h>

#include <fstream>

#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam::bench {
namespace {

// Ground truth at 10 Hz for 30 s with constant biases bg = (0.002, 0, 0), ba = (0, 0.05, 0).
Trajectory TruthWithBiases() {
  Trajectory gt;
  for (int i = 0; i <= 300; ++i) {
    gt.poses.push_back({1000000000LL * 100 + 100000000LL * i, SE3d()});
    GroundTruthExtras x;
    x.gyro_bias = Eigen::Vector3d(0.002, 0, 0);
    x.accel_bias = Eigen::Vector3d(0, 0.05, 0);
    gt.extras.push_back(x);
  }
  return gt;
}

TEST(BiasEvaluation, MeanRelativeErrorOfInitialisedKeyFramesAfterTheDelay) {
  const auto dir = testing::MakeTempDir("bias_eval");
  const auto file = dir / "keyframes_imu.csv";
  std::ofstream(file) << "time,vx,vy,vz,bgx,bgy,bgz,bax,bay,baz,valid,map_imu_initialized\n"
                         // first keyframe at 100 s; 5 s: before the 15 s delay (ignored)
                         "100.000000000,0,0,0,0,0,0,0,0,0,1,0\n"
                         "105.000000000,0,0,0,9,9,9,9,9,9,1,1\n"
                         // 20 s: gyro 10% off, accel 20% off
                         "120.000000000,0,0,0,0.0022,0,0,0,0.06,0,1,1\n"
                         // 25 s: gyro 30% off, accel exact
                         "125.000000000,0,0,0,0.002,0.0006,0,0,0.05,0,1,1\n"
                         // 26 s but the map's IMU is not initialised (a new map): ignored
                         "126.000000000,0,0,0,1,1,1,1,1,1,1,0\n";
  const auto e = EvaluateBiases(file, TruthWithBiases(), 15.0);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->keyframes, 2);
  EXPECT_NEAR(e->gyro_pct, 20.0, 1e-6);
  EXPECT_NEAR(e->accel_pct, 10.0, 1e-6);
}

TEST(BiasEvaluation, NothingToEvaluateAndMalformedFiles) {
  const auto dir = testing::MakeTempDir("bias_eval_bad");
  EXPECT_FALSE(EvaluateBiases(dir / "missing.csv", TruthWithBiases(), 15.0).has_value());
  Trajectory no_biases = TruthWithBiases();
  no_biases.extras.clear();
  std::ofstream(dir / "ok.csv")
      << "time,vx,vy,vz,bgx,bgy,bgz,bax,bay,baz,valid,map_imu_initialized\n"
         "100.0,0,0,0,0,0,0,0,0,0,1,1\n";
  EXPECT_FALSE(EvaluateBiases(dir / "ok.csv", no_biases, 0.0).has_value());
  std::ofstream(dir / "bad.csv")
      << "time,vx,vy,vz,bgx,bgy,bgz,bax,bay,baz,valid,map_imu_initialized\n"
         "100.0,0,0,0,0,0,0,0,0,0,1,1\n"
         "101.0,0,0,0,x,0,0,0,0,0,1,1\n";
  try {
    EvaluateBiases(dir / "bad.csv", TruthWithBiases(), 0.0);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 3u) << e.what();
  }
}

}  // namespace
}  // namespace pkslam::bench
