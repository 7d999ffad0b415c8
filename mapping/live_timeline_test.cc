// LiveTimeline: local mapping's counted work laid out on the data clock.
#include "mapping/live_timeline.h"

#include <gtest/gtest.h>

#include <chrono>
#include <limits>
#include <thread>

namespace pkslam {
namespace {

constexpr std::int64_t kMsNs = 1'000'000;

// A unit of keyframe work costs 125 ms on the emulated machine (exact in binary, so the data
// times below are exact); nothing else costs anything.
const WorkModel kEighthPerKeyFrame{{0.125, 0.0, 0.0, 0.0}};

TEST(LiveTimeline, AJobSpansItsPricedWorkTimesThePaceFromItsStamp) {
  WorkMeter work;
  LiveTimeline timeline(LiveEmulation{true, 2.0, LiveClock::kWork}, &work, kEighthPerKeyFrame);
  work.Add(WorkKind::kKeyFrame, 5);           // work done before the job does not count in it
  work.Add(WorkKind::kSolverResidual, 1000);  // priced at nothing here
  timeline.StartJob(1'000 * kMsNs);
  EXPECT_EQ(timeline.ReachedNs(), 1'000 * kMsNs);
  work.Add(WorkKind::kKeyFrame, 2);  // 250 ms of work, at pace 2: 500 ms of data
  EXPECT_EQ(timeline.ReachedNs(), 1'500 * kMsNs);
  timeline.EndJob();
  EXPECT_FALSE(timeline.FreeBy(1'499 * kMsNs));
  EXPECT_TRUE(timeline.FreeBy(1'500 * kMsNs));
}

TEST(LiveTimeline, AJobStartsWhenThePreviousEndedIfThatIsLater) {
  WorkMeter work;
  LiveTimeline timeline(LiveEmulation{true, 1.0, LiveClock::kWork}, &work, kEighthPerKeyFrame);
  timeline.StartJob(0);
  work.Add(WorkKind::kKeyFrame, 8);  // busy until 1 s of data
  timeline.EndJob();
  // A keyframe stamped 0.5 s waits for the previous one: it starts at 1 s.
  timeline.StartJob(500 * kMsNs);
  work.Add(WorkKind::kKeyFrame, 1);
  EXPECT_EQ(timeline.ReachedNs(), 1'125 * kMsNs);
  timeline.EndJob();
  // One stamped after that starts at its own stamp.
  timeline.StartJob(3'000 * kMsNs);
  EXPECT_EQ(timeline.ReachedNs(), 3'000 * kMsNs);
  // A reset forgets where the last job ended: the next starts at its stamp even if earlier.
  timeline.EndJob();
  timeline.Reset();
  EXPECT_TRUE(timeline.FreeBy(std::numeric_limits<std::int64_t>::min()));
  timeline.StartJob(200 * kMsNs);
  EXPECT_EQ(timeline.ReachedNs(), 200 * kMsNs);
}

TEST(LiveTimeline, TrackingsTimeOnlyGrows) {
  WorkMeter work;
  LiveTimeline timeline(LiveEmulation{true, 1.0, LiveClock::kWork}, &work);
  EXPECT_TRUE(timeline.TrackerBefore(std::numeric_limits<std::int64_t>::min() + 1));
  EXPECT_TRUE(timeline.AdvanceTracker(100));
  EXPECT_FALSE(timeline.AdvanceTracker(100));  // not a step forward
  EXPECT_FALSE(timeline.AdvanceTracker(50));   // a frame already passed
  EXPECT_TRUE(timeline.TrackerBefore(101));
  EXPECT_FALSE(timeline.TrackerBefore(100));
  EXPECT_TRUE(timeline.AdvanceTracker(200));
  EXPECT_FALSE(timeline.TrackerBefore(150));
}

// The work clock is woken by the meter, so a waiter only needs a short bound; the CPU and wall
// clocks cannot run faster than real time, so a waiter sleeps for the data time still to go,
// divided by the pace.
TEST(LiveTimeline, TrackingRechecksAfterTheDataTimeStillToGoOnTimedClocks) {
  WorkMeter work;
  const LiveTimeline counted(LiveEmulation{true, 2.0, LiveClock::kWork}, &work);
  EXPECT_DOUBLE_EQ(counted.RecheckSeconds(1'000 * kMsNs, 0), 0.002);
  const LiveTimeline timed(LiveEmulation{true, 2.0, LiveClock::kWall}, &work);
  EXPECT_DOUBLE_EQ(timed.RecheckSeconds(1'000 * kMsNs, 200 * kMsNs), 0.4);
  EXPECT_TRUE(LiveEmulation({true, 1.0, LiveClock::kWork}).paced());
  EXPECT_FALSE(LiveEmulation({true, 1.0, LiveClock::kCpu}).paced());
  EXPECT_FALSE(LiveEmulation({false, 1.0, LiveClock::kWork}).paced());
  EXPECT_EQ(LiveEmulation({true, 1.5, LiveClock::kWork}).DataNs(2.0), 3'000 * kMsNs);
}

// The wall clock counts time whether or not any work was counted.
TEST(LiveTimeline, TheWallClockCountsElapsedTimeNotWork) {
  WorkMeter work;
  LiveTimeline timeline(LiveEmulation{true, 1.0, LiveClock::kWall}, &work, kEighthPerKeyFrame);
  timeline.StartJob(0);
  work.Add(WorkKind::kKeyFrame, 80);  // 10 s of priced work: not what this clock reads
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const std::int64_t reached = timeline.ReachedNs();
  EXPECT_GE(reached, 20 * kMsNs);
  EXPECT_LT(reached, 10'000 * kMsNs);
}

TEST(LiveTimeline, ParsesTheClockNames) {
  EXPECT_EQ(ParseLiveClock("work"), LiveClock::kWork);
  EXPECT_EQ(ParseLiveClock("cpu"), LiveClock::kCpu);
  EXPECT_EQ(ParseLiveClock("wall"), LiveClock::kWall);
  EXPECT_FALSE(ParseLiveClock("Wall").has_value());
  EXPECT_FALSE(ParseLiveClock("").has_value());
}

}  // namespace
}  // namespace pkslam
