// LocalMapper's live emulation (offline runs, MappingBackend::AcceptsKeyFramesAt): local
// mapping's work laid out on the data clock decides whether tracking at a frame's time finds it
// busy, as a live run would, whatever the wall clock says.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "core/util/cpu_time.h"
#include "map_model/keyframe.h"
#include "map_model/testing/synthetic_map.h"
#include "mapping/local_mapper.h"

namespace pkslam {
namespace {

using namespace std::chrono_literals;

constexpr std::int64_t kMs = 1'000'000;

// Three keyframes of a synthetic stereo map (50 ms apart on the data clock).
struct Fixture {
  Atlas atlas;
  std::shared_ptr<CameraRig> rig = testing::MakeStereoRig();
  testing::SyntheticMap map;

  Fixture() {
    const testing::SyntheticScene scene = testing::MakeScene(400, 3);
    std::vector<SE3d> camera_from_world;
    for (int k = 0; k < 3; ++k) {
      camera_from_world.push_back(SE3d(SO3d(), Eigen::Vector3d(-0.1 * k, 0.0, 0.0)));
    }
    map = testing::MakeMap(&atlas, scene, rig, camera_from_world, testing::FrameOptions());
  }
};

// Keeps the calling thread computing for `work` of its own CPU time.
void Compute(std::chrono::milliseconds work) {
  const double end = ThreadCpuSeconds() + std::chrono::duration<double>(work).count();
  volatile double sink = 0;
  while (ThreadCpuSeconds() < end) sink = sink + 1.0;
}

// A started mapper whose every keyframe takes at least `work` (the consumer runs inside the
// processing): computing (CPU time) or, with `sleep`, sleeping (wall time only); live
// emulation at `pace` (0: off) on `clock`.
std::unique_ptr<LocalMapper> StartMapper(Fixture* f, std::chrono::milliseconds work, double pace,
                                         bool sleep = false, LiveClock clock = LiveClock::kCpu) {
  LocalMappingOptions options;
  options.cull_keyframes = false;
  auto mapper = std::make_unique<LocalMapper>(&f->atlas, f->rig, options);
  mapper->SetKeyFrameConsumer([work, sleep](const KeyFramePtr&) {
    if (sleep) {
      std::this_thread::sleep_for(work);
    } else {
      Compute(work);
    }
  });
  if (pace > 0) mapper->EmulateLive(true, pace, clock);
  mapper->Start();
  return mapper;
}

TEST(LocalMapperLive, BusyOnTheDataClockForTheCpuTimeOfItsWork) {
  Fixture f;
  auto owned = StartMapper(&f, 1000ms, 1.0);
  LocalMapper& mapper = *owned;
  const std::int64_t t0 = f.map.keyframes[0]->t_ns();
  mapper.InsertKeyFrame(f.map.keyframes[0]);
  // 100 ms of data later a live run would still be mapping the keyframe (it takes >= 1 s):
  // busy, known once 100 ms of its work have passed, long before it ends.
  EXPECT_FALSE(mapper.AcceptsKeyFramesAt(t0 + 100 * kMs));
  EXPECT_FALSE(mapper.AcceptsKeyFrames());  // still working: the answer did not wait for it
  // 10 s of data later it would be idle: the call waits for the work to end, then says so.
  EXPECT_TRUE(mapper.AcceptsKeyFramesAt(t0 + 10'000 * kMs));
  EXPECT_TRUE(mapper.AcceptsKeyFrames());
  // Idle now on the wall clock, but its work spans >= 1 s of data from t0: a frame 500 ms
  // after t0 still finds it busy.
  EXPECT_FALSE(mapper.AcceptsKeyFramesAt(t0 + 500 * kMs));
  // A keyframe inserted later starts when it arrives on the data clock (or when the previous
  // one ends, whichever is later): 1.1 s after t0 it starts at >= t0 + 1 s.
  mapper.InsertKeyFrame(f.map.keyframes[1]);
  EXPECT_FALSE(mapper.AcceptsKeyFramesAt(t0 + 1'500 * kMs));
  EXPECT_TRUE(mapper.AcceptsKeyFramesAt(t0 + 60'000 * kMs));
  EXPECT_GT(mapper.live_wait_ms(), 500.0);
  mapper.Finish();
}

// Pace 2: the emulated live run gets frames twice as fast, so the same work spans twice the
// data time.
TEST(LocalMapperLive, PaceScalesTheDataTimeOfTheWork) {
  Fixture f;
  auto owned = StartMapper(&f, 300ms, 2.0);
  LocalMapper& mapper = *owned;
  const std::int64_t t0 = f.map.keyframes[0]->t_ns();
  mapper.InsertKeyFrame(f.map.keyframes[0]);
  EXPECT_TRUE(mapper.AcceptsKeyFramesAt(t0 + 10'000 * kMs));  // waits for the end
  EXPECT_FALSE(mapper.AcceptsKeyFramesAt(t0 + 500 * kMs));    // >= 300 ms x 2 of data
  mapper.Finish();
}

// The CPU clock counts work, not waiting: a keyframe whose processing only sleeps spans no
// data time, so a frame 100 ms later finds mapping idle once it is done; on the wall clock
// (--live-clock wall) the same sleep spans 300 ms of data, as a loaded machine would.
TEST(LocalMapperLive, CpuClockIgnoresTimeNotSpentWorking) {
  {
    Fixture f;
    auto owned = StartMapper(&f, 300ms, 1.0, /*sleep=*/true);
    const std::int64_t t0 = f.map.keyframes[0]->t_ns();
    owned->InsertKeyFrame(f.map.keyframes[0]);
    EXPECT_TRUE(owned->AcceptsKeyFramesAt(t0 + 100 * kMs));
    owned->Finish();
  }
  {
    Fixture f;
    auto owned = StartMapper(&f, 300ms, 1.0, /*sleep=*/true, LiveClock::kWall);
    const std::int64_t t0 = f.map.keyframes[0]->t_ns();
    owned->InsertKeyFrame(f.map.keyframes[0]);
    EXPECT_FALSE(owned->AcceptsKeyFramesAt(t0 + 100 * kMs));
    EXPECT_TRUE(owned->AcceptsKeyFramesAt(t0 + 10'000 * kMs));
    owned->Finish();
  }
}

// The work clock (the default) prices the work local mapping counted (kReferenceWork), not the
// time it took: a keyframe whose processing also computes for 300 ms of CPU spans only its
// priced work in data time (times the pace), which is the same on any machine.
TEST(LocalMapperLive, WorkClockSpansThePricedWorkOnly) {
  Fixture f;
  auto owned = StartMapper(&f, 300ms, 2.0, /*sleep=*/false, LiveClock::kWork);
  LocalMapper& mapper = *owned;
  const std::int64_t t0 = f.map.keyframes[0]->t_ns();
  mapper.InsertKeyFrame(f.map.keyframes[0]);
  mapper.WaitUntilIdle();
  const LocalMappingStats stats = mapper.stats();
  ASSERT_EQ(stats.keyframe_work.size(), 1u);
  EXPECT_EQ(stats.keyframe_work[0][static_cast<std::size_t>(WorkKind::kKeyFrame)], 1);
  const double priced_s = kReferenceWork.Seconds(stats.keyframe_work[0]);
  EXPECT_GT(priced_s, 0.0);
  EXPECT_LT(priced_s, 0.1);  // far below the 300 ms the CPU clock would have counted
  const auto span_ns = static_cast<std::int64_t>(2.0 * priced_s * 1e9);
  EXPECT_FALSE(mapper.AcceptsKeyFramesAt(t0 + span_ns / 2));
  EXPECT_TRUE(mapper.AcceptsKeyFramesAt(t0 + span_ns + kMs));
  mapper.Finish();
}

// On the work clock local mapping is paced: it does not change the map at a data time tracking
// has not reached yet, however fast this machine is.
TEST(LocalMapperLive, WorkClockHoldsMappingBackToTrackingsTime) {
  Fixture f;
  auto owned = StartMapper(&f, 0ms, 1.0, /*sleep=*/false, LiveClock::kWork);
  LocalMapper& mapper = *owned;
  const std::int64_t t0 = f.map.keyframes[0]->t_ns();
  mapper.NoteFrameTime(t0 - 1'000 * kMs);  // tracking is a second behind the keyframe
  mapper.InsertKeyFrame(f.map.keyframes[0]);
  std::this_thread::sleep_for(300ms);
  EXPECT_FALSE(mapper.AcceptsKeyFrames());          // still holding the keyframe
  EXPECT_TRUE(mapper.stats().keyframe_work.empty());  // not processed
  mapper.NoteFrameTime(t0 + 10'000 * kMs);
  EXPECT_TRUE(mapper.AcceptsKeyFramesAt(t0 + 10'000 * kMs));
  EXPECT_EQ(mapper.stats().keyframe_work.size(), 1u);
  mapper.Finish();
}

// Without emulation the answer is the wall-clock state, whatever the data time.
TEST(LocalMapperLive, OffMeansAcceptsKeyFrames) {
  Fixture f;
  auto owned = StartMapper(&f, 300ms, 0.0);
  LocalMapper& mapper = *owned;
  const std::int64_t t0 = f.map.keyframes[0]->t_ns();
  EXPECT_TRUE(mapper.AcceptsKeyFramesAt(t0));
  mapper.InsertKeyFrame(f.map.keyframes[0]);
  std::this_thread::sleep_for(50ms);
  EXPECT_FALSE(mapper.AcceptsKeyFramesAt(t0 + 60'000 * kMs));  // busy now; no waiting
  mapper.WaitUntilIdle();
  EXPECT_TRUE(mapper.AcceptsKeyFramesAt(t0));
  EXPECT_DOUBLE_EQ(mapper.live_wait_ms(), 0.0);
  mapper.Finish();
}

}  // namespace
}  // namespace pkslam
