// OnlineCalibrator on its own: the schedule (first span, growth, a queued keyframe first), an
// adjustment solved in the step, and a paced adjustment that waits for the data clock.
#include "mapping/online_calibrator.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <limits>
#include <thread>

#include "map_model/keyframe.h"
#include "mapping/calibration_test_map.h"
#include "mapping/local_mapper.h"

namespace pkslam {
namespace {

using namespace std::chrono_literals;

class OnlineCalibratorTest : public ::testing::Test {
 protected:
  OnlineCalibrationOptions Options(double first_after_s = 0.1) const {
    OnlineCalibrationOptions options;
    options.enabled = true;
    options.first_after_s = first_after_s;
    return options;
  }

  std::unique_ptr<OnlineCalibrator> Calibrator(const OnlineCalibrationOptions& options) {
    auto calibrator =
        std::make_unique<OnlineCalibrator>(&map_.atlas, Sensor::kStereo, options, /*threads=*/1);
    calibrator->SetPrior(map_.file, map_.shape);
    return calibrator;
  }

  // Paced on a data clock the test moves: local mapping's work "reaches" `reached_ns_`.
  void Pace(OnlineCalibrator* calibrator) {
    CalibrationPacing pacing;
    pacing.paced = true;
    pacing.position = [this] { return LiveDataPosition{reached_ns_.load(), stopping_.load()}; };
    pacing.data_ns = [](const WorkCounts& work) {
      return static_cast<std::int64_t>(kReferenceWork.Seconds(work) * 1e9);
    };
    calibrator->SetPacing(std::move(pacing));
  }

  // Waits (up to 60 s) for the calibration thread to end its solve.
  static void WaitForSolve(const OnlineCalibrator& calibrator) {
    const auto deadline = std::chrono::steady_clock::now() + 60s;
    while (calibrator.Running() && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(5ms);
    }
    ASSERT_FALSE(calibrator.Running());
  }

  const KeyFramePtr& Last() const { return map_.map.keyframes.back(); }  // spans 0.55 s

  testing::CalibrationTestMap map_;
  std::atomic<std::int64_t> reached_ns_{0};
  std::atomic<bool> stopping_{false};
};

TEST_F(OnlineCalibratorTest, InTheStepItAppliesAndWaitsForTheSpanToGrow) {
  auto calibrator = Calibrator(Options());
  const int version = map_.atlas.calibration_version();
  calibrator->Step(Last(), /*keyframe_queued=*/false, /*in_step=*/true, nullptr, nullptr);
  auto history = calibrator->history();
  ASSERT_EQ(history.size(), 1u);
  EXPECT_TRUE(history[0].applied) << history[0].note;
  EXPECT_EQ(history[0].keyframes, 12);
  EXPECT_NEAR(history[0].span_s, 0.55, 1e-9);
  EXPECT_GT(map_.atlas.calibration_version(), version);  // the map moved to the estimate
  EXPECT_FALSE(calibrator->Outstanding());
  // The next one is due at 1.5 times the span: the same keyframe again starts none.
  calibrator->Step(Last(), false, true, nullptr, nullptr);
  EXPECT_EQ(calibrator->history().size(), 1u);
}

TEST_F(OnlineCalibratorTest, NothingBeforeTheFirstSpanOrWhileAKeyFrameIsQueued) {
  auto late = Calibrator(Options(/*first_after_s=*/0.6));
  late->Step(Last(), false, true, nullptr, nullptr);
  EXPECT_TRUE(late->history().empty());  // 0.55 s of data < 0.6 s
  auto calibrator = Calibrator(Options());
  const int version = map_.atlas.calibration_version();
  calibrator->Step(Last(), /*keyframe_queued=*/true, true, nullptr, nullptr);
  EXPECT_TRUE(calibrator->history().empty());
  EXPECT_EQ(map_.atlas.calibration_version(), version);
  // The keyframe after it does the adjustment the queued one put off.
  calibrator->Step(Last(), false, true, nullptr, nullptr);
  EXPECT_EQ(calibrator->history().size(), 1u);
}

TEST_F(OnlineCalibratorTest, PacedItLandsOnlyOnceTheDataClockPassedItsWork) {
  auto calibrator = Calibrator(Options());
  Pace(calibrator.get());
  const int version = map_.atlas.calibration_version();
  calibrator->Step(Last(), false, /*in_step=*/false, nullptr, nullptr);
  EXPECT_TRUE(calibrator->Outstanding());
  WaitForSolve(*calibrator);
  // Solved on this machine, but local mapping's data clock has not moved since it started.
  calibrator->ApplyDue();
  EXPECT_TRUE(calibrator->Outstanding());
  EXPECT_EQ(map_.atlas.calibration_version(), version);
  EXPECT_TRUE(calibrator->history().empty());
  // Past its work, but local mapping is stopping: it waits.
  reached_ns_ = std::numeric_limits<std::int64_t>::max() / 2;
  stopping_ = true;
  calibrator->ApplyDue();
  EXPECT_TRUE(calibrator->Outstanding());
  stopping_ = false;
  calibrator->ApplyDue();
  EXPECT_FALSE(calibrator->Outstanding());
  const auto history = calibrator->history();
  ASSERT_EQ(history.size(), 1u);
  EXPECT_TRUE(history[0].applied) << history[0].note;
  EXPECT_GT(map_.atlas.calibration_version(), version);
}

TEST_F(OnlineCalibratorTest, StopDropsAPacedResultNotYetDue) {
  auto calibrator = Calibrator(Options());
  Pace(calibrator.get());
  const int version = map_.atlas.calibration_version();
  calibrator->Step(Last(), false, false, nullptr, nullptr);
  WaitForSolve(*calibrator);
  calibrator->Stop();
  EXPECT_FALSE(calibrator->Outstanding());
  const auto history = calibrator->history();
  ASSERT_EQ(history.size(), 1u);
  EXPECT_FALSE(history[0].applied);
  EXPECT_EQ(history[0].note, "not applied: the run ended or reset before it was due");
  EXPECT_EQ(map_.atlas.calibration_version(), version);
}

}  // namespace
}  // namespace pkslam
