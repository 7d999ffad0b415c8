// LocalMapper's online calibration: the adjustment gathered in the keyframe step, solved in a
// thread of its own (OnlineCalibrationOptions::own_thread) or inside the step, and applied.
#include <gtest/gtest.h>

#include <chrono>
#include <limits>
#include <memory>
#include <thread>

#include "map_model/keyframe.h"
#include "mapping/calibration_test_map.h"
#include "mapping/local_mapper.h"

namespace pkslam {
namespace {

using namespace std::chrono_literals;

// The calibration test map, with a mapper that calibrates it.
struct CalibrationMapFixture : testing::CalibrationTestMap {
  // A started mapper with online calibration due from the start (0.1 s of data). `paced`: live
  // emulation on the work clock, tracking far ahead (so pacing never waits for it).
  std::unique_ptr<LocalMapper> StartMapper(bool own_thread, bool paced = false) {
    LocalMappingOptions options;
    options.cull_keyframes = false;
    options.calibration.enabled = true;
    options.calibration.first_after_s = 0.1;
    options.calibration.own_thread = own_thread;
    auto mapper = std::make_unique<LocalMapper>(&atlas, setup.rig, options);
    mapper->SetCalibrationPrior(file, shape);
    if (paced) mapper->EmulateLive(true, 1.0, LiveClock::kWork);
    mapper->Start();
    if (paced) mapper->NoteFrameTime(std::numeric_limits<std::int64_t>::max() / 2);
    return mapper;
  }
};

class LocalMapperCalibrationTest : public ::testing::Test {
 protected:
  std::unique_ptr<LocalMapper> StartMapper(bool own_thread) {
    return fixture_.StartMapper(own_thread);
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

  CalibrationMapFixture fixture_;
  Atlas& atlas_ = fixture_.atlas;
  testing::SyntheticMap& map_ = fixture_.map;
};

// Paced (live emulation on the work clock), own thread: the number of keyframe steps local
// mapping takes before the adjustment started with the first one is applied, -1 if none of 60.
int KeyFrameStepsUntilPacedApply(int* applied_steps_after) {
  CalibrationMapFixture f;
  auto mapper = f.StartMapper(/*own_thread=*/true, /*paced=*/true);
  const int version = f.atlas.calibration_version();
  mapper->InsertKeyFrame(f.map.keyframes.back());
  mapper->WaitUntilIdle();
  // Started at the step's data time, due only once local mapping's work has passed its own:
  // not applied within the step that started it, however fast this machine solved it.
  EXPECT_EQ(f.atlas.calibration_version(), version);
  int steps = -1;
  for (int k = 1; k <= 60 && steps < 0; ++k) {
    mapper->InsertKeyFrame(f.map.keyframes[static_cast<std::size_t>(k % 11)]);
    mapper->WaitUntilIdle();
    if (f.atlas.calibration_version() != version) steps = k;
  }
  mapper->Finish();
  const auto adjustments = mapper->stats().calibration_refinements;
  *applied_steps_after = adjustments.empty() || !adjustments[0].applied ? 0 : 1;
  return steps;
}

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

TEST_F(LocalMapperCalibrationTest, PacedTheAdjustmentLandsAtTheSameStepOnAnyMachine) {
  // Applied by local mapping once its data time passes the start plus the solve's work priced
  // on the reference machine: the step it lands at depends on counted work only, not on how
  // fast this machine (or the sanitizers' slowdown) solved it, so two runs agree.
  int applied_first = 0;
  int applied_second = 0;
  const int first = KeyFrameStepsUntilPacedApply(&applied_first);
  const int second = KeyFrameStepsUntilPacedApply(&applied_second);
  ASSERT_GT(first, 0) << "the adjustment never landed";
  EXPECT_EQ(applied_first, 1);
  EXPECT_EQ(second, first);
  EXPECT_EQ(applied_second, 1);
}

}  // namespace
}  // namespace pkslam
