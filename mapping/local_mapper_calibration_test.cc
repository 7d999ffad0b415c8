// LocalMapper's online calibration: the adjustment gathered in the keyframe step, solved in a
// thread of its own (OnlineCalibrationOptions::own_thread) or inside the step, and applied.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <thread>

#include "core/sensor/test_rig_calibration.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/testing/synthetic_map.h"
#include "mapping/local_mapper.h"

namespace pkslam {
namespace {

using namespace std::chrono_literals;

// Twelve keyframes of a stereo map built in the rectified camera of the EuRoC calibration,
// which the Atlas and the mapper's prior hold (12 x 50 ms of data).
class LocalMapperCalibrationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    file_ = testing::EurocRigCalibration();
    shape_.sensor = Sensor::kStereo;
    shape_.pyramid = ScalePyramid(8, 1.2);
    setup_ = BuildRig(file_, shape_);
    {
      auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
      atlas_.SetCalibration(file_, setup_);
    }
    testing::FrameOptions frames;
    frames.pixel_noise = 0.5;
    map_ = testing::MakeMap(&atlas_, testing::MakeScene(600, 11), setup_.rig,
                            testing::MakeForwardPath(12, 0.15, 3), frames);
  }

  // A started mapper with online calibration due from the start (0.1 s of data).
  std::unique_ptr<LocalMapper> StartMapper(bool own_thread) {
    LocalMappingOptions options;
    options.cull_keyframes = false;
    options.calibration.enabled = true;
    options.calibration.first_after_s = 0.1;
    options.calibration.own_thread = own_thread;
    auto mapper = std::make_unique<LocalMapper>(&atlas_, setup_.rig, options);
    mapper->SetCalibrationPrior(file_, shape_);
    mapper->Start();
    return mapper;
  }

  // Waits (up to 60 s) until the mapper has recorded `count` adjustments.
  static std::vector<CalibrationRefinementStat> WaitForAdjustments(const LocalMapper& mapper,
                                                                   std::size_t count) {
    const auto deadline = std::chrono::steady_clock::now() + 60s;
    while (mapper.stats().calibration_refinements.size() < count &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(10ms);
    }
    return mapper.stats().calibration_refinements;
  }

  Atlas atlas_;
  RigCalibration file_;
  RigShape shape_;
  RigSetup setup_;
  testing::SyntheticMap map_;
};

TEST_F(LocalMapperCalibrationTest, AnAdjustmentInItsOwnThreadIsApplied) {
  auto mapper = StartMapper(/*own_thread=*/true);
  const int version = atlas_.calibration_version();
  mapper->InsertKeyFrame(map_.keyframes.back());
  mapper->WaitUntilIdle();
  const auto adjustments = WaitForAdjustments(*mapper, 1);
  ASSERT_EQ(adjustments.size(), 1u);
  EXPECT_TRUE(adjustments[0].applied) << adjustments[0].note;
  EXPECT_EQ(adjustments[0].keyframes, 12);
  EXPECT_GT(adjustments[0].iterations, 0);
  EXPECT_GT(atlas_.calibration_version(), version);  // the map moved to the estimate
  // Mapping goes on after it: the next keyframe is processed and, the span not having grown by
  // the schedule's factor, starts no second adjustment.
  mapper->InsertKeyFrame(map_.keyframes[10]);
  mapper->WaitUntilIdle();
  mapper->Finish();
  EXPECT_EQ(mapper->stats().calibration_refinements.size(), 1u);
}

TEST_F(LocalMapperCalibrationTest, InsideTheStepTheSameAdjustmentIsApplied) {
  auto mapper = StartMapper(/*own_thread=*/false);
  const int version = atlas_.calibration_version();
  mapper->InsertKeyFrame(map_.keyframes.back());
  mapper->WaitUntilIdle();  // the adjustment ran inside the step: it has ended
  const auto adjustments = mapper->stats().calibration_refinements;
  ASSERT_EQ(adjustments.size(), 1u);
  EXPECT_TRUE(adjustments[0].applied) << adjustments[0].note;
  EXPECT_GT(atlas_.calibration_version(), version);
  mapper->Finish();
}

TEST_F(LocalMapperCalibrationTest, AResetOrFinishWhileItSolvesEndsItCleanly) {
  // Under the sanitizers ('threaded' label): the reset and Finish stop the calibration thread
  // before the queue (and the map) go, whatever point the solve has reached.
  auto mapper = StartMapper(/*own_thread=*/true);
  mapper->InsertKeyFrame(map_.keyframes.back());
  mapper->WaitUntilIdle();
  mapper->ResetQueue();
  mapper->Finish();
  const auto adjustments = mapper->stats().calibration_refinements;
  ASSERT_EQ(adjustments.size(), 1u);  // recorded however it ended
  EXPECT_FALSE(adjustments[0].note.empty() && !adjustments[0].applied);
}

}  // namespace
}  // namespace pkslam
