#include "loopclosing/loop_closing.h"

#include <gtest/gtest.h>

#include <atomic>

#include "core/util/error.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

using testing::FrameOptions;
using testing::MakeForwardPath;
using testing::MakeMap;
using testing::MakeScene;
using testing::MakeStereoRig;

TEST(LoopClosingOptions, RejectsBadValues) {
  LoopClosingOptions o;
  EXPECT_NO_THROW(o.Check());
  o.confirmations = 0;
  EXPECT_THROW(o.Check(), OptionError);
  o = LoopClosingOptions{};
  o.verifier.min_bow_matches = 2;  // RANSAC needs three pairs
  EXPECT_THROW(o.Check(), OptionError);
  o = LoopClosingOptions{};
  o.fuse_radius = 0;
  EXPECT_THROW(o.Check(), OptionError);
}

// Keyframes handed over by local mapping are all processed, in threaded and synchronous mode,
// and WaitUntilIdle / Finish return; with no place seen twice (and no database) nothing is
// corrected and local mapping is never paused.
class LoopClosingThreadTest : public ::testing::TestWithParam<bool> {};

TEST_P(LoopClosingThreadTest, ProcessesEveryKeyFrameWithoutPausingMapping) {
  Atlas atlas;
  const auto map =
      MakeMap(&atlas, MakeScene(500, 3), MakeStereoRig(), MakeForwardPath(8, 0.2, 4), {});
  std::atomic<int> stop_requests{0};
  MappingControl control;
  control.request_stop = [&] { ++stop_requests; };
  control.is_stopped = [] { return true; };
  control.release = [] {};
  LoopClosingOptions options;
  options.synchronous = GetParam();
  LoopClosing loop(&atlas, Sensor::kStereo, control, options);
  loop.Start();
  for (const auto& kf : map.keyframes) loop.InsertKeyFrame(kf);
  loop.WaitUntilIdle();
  EXPECT_EQ(loop.stats().keyframes, static_cast<int>(map.keyframes.size()));
  loop.Finish();
  const LoopClosingStats stats = loop.stats();
  EXPECT_EQ(stats.keyframes, static_cast<int>(map.keyframes.size()));
  EXPECT_TRUE(stats.loops.empty());
  EXPECT_TRUE(stats.merges.empty());
  EXPECT_EQ(stop_requests.load(), 0);
}

INSTANTIATE_TEST_SUITE_P(Modes, LoopClosingThreadTest, ::testing::Values(false, true));

}  // namespace
}  // namespace pkslam
