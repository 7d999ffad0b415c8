// Tracking's overrides of the selector: a starving monocular map gets a keyframe, a full queue
// gets none, and the trace records what was decided.
#include "tracking/keyframe_decision.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace pkslam {
namespace {

// A selector that answers what the test sets.
class ScriptedSelector : public KeyframeSelector {
 public:
  std::string_view name() const override { return "scripted"; }
  SelectorDecision Decide(const SelectorInput&) override { return answer; }
  SelectorDecision answer;
};

// A monocular frame with local mapping busy, tracking 40 of the reference keyframe's 100 points.
SelectorInput BusyMonocularFrame() {
  SelectorInput in;
  in.frame_id = 12;
  in.t_ns = 600'000'000;
  in.last_keyframe_frame_id = 7;
  in.local_mapping_idle = false;
  in.reference_tracked_points = 100;
  return in;
}

SelectorDecision Busy() {
  SelectorDecision d = SelectorDecision::No("busy");
  d.deferred_busy = true;
  return d;
}

TEST(KeyFrameDecision, AStarvingMonocularMapGetsAKeyFrameWhileMappingIsBusy) {
  const StarvingRule rule{75, 0.5};
  const SelectorInput in = BusyMonocularFrame();
  EXPECT_TRUE(MapStarving(Busy(), in, /*inliers=*/40, rule));          // under 75 and under half
  EXPECT_TRUE(MapStarving(SelectorDecision::No("no"), in, 40, rule));  // under half of 100
  EXPECT_FALSE(MapStarving(SelectorDecision::No("no"), in, 60, rule));
  EXPECT_TRUE(MapStarving(Busy(), in, 60, rule));  // deferred only for busy, 60 < 75
  EXPECT_FALSE(MapStarving(Busy(), in, 80, rule));
  SelectorInput idle = in;
  idle.local_mapping_idle = true;
  EXPECT_FALSE(MapStarving(Busy(), idle, 40, rule));
  SelectorInput behind = in;
  behind.local_mapping_queue = 3;
  EXPECT_FALSE(MapStarving(Busy(), behind, 40, rule));

  ScriptedSelector selector;
  selector.answer = Busy();
  KeyFrameDecision mono(/*monocular=*/true, rule);
  bool declined = false;
  const SelectorDecision& d = mono.Decide(
      selector, in, 40, [] { return false; }, &declined);
  EXPECT_TRUE(d.insert);
  EXPECT_TRUE(d.interrupt_local_ba);
  EXPECT_EQ(d.reason, "busy;starving");
  KeyFrameDecision stereo(/*monocular=*/false, rule);
  EXPECT_FALSE(stereo
                   .Decide(
                       selector, in, 40, [] { return false; }, &declined)
                   .insert);
  EXPECT_FALSE(declined);
}

TEST(KeyFrameDecision, AFullQueueDeclinesAndIsAskedOnlyWhenAKeyFrameIsWanted) {
  ScriptedSelector selector;
  KeyFrameDecision decision(false, StarvingRule{});
  int asked = 0;
  const auto full = [&] {
    ++asked;
    return true;
  };
  bool declined = false;
  selector.answer = SelectorDecision::No("no");
  decision.Decide(selector, BusyMonocularFrame(), 200, full, &declined);
  EXPECT_EQ(asked, 0);
  EXPECT_FALSE(declined);
  selector.answer.insert = true;
  selector.answer.reason = "c1";
  EXPECT_FALSE(decision.Decide(selector, BusyMonocularFrame(), 200, full, &declined).insert);
  EXPECT_EQ(asked, 1);
  EXPECT_TRUE(declined);
  EXPECT_EQ(decision.last().reason, "c1");
}

TEST(KeyFrameDecision, TheTraceRecordsEachDecisionWhenAsked) {
  ScriptedSelector selector;
  selector.answer = SelectorDecision::No("no");
  selector.answer.trace = {{"criterion1", 1.0}, {"criterion2", 0.0}, {"dc", 0.3}};
  KeyFrameDecision decision(false, StarvingRule{});
  bool declined = false;
  decision.Decide(
      selector, BusyMonocularFrame(), 200, [] { return false; }, &declined);
  EXPECT_TRUE(decision.trace().empty());
  decision.EnableTrace(true);
  decision.Decide(
      selector, BusyMonocularFrame(), 200, [] { return false; }, &declined);
  ASSERT_EQ(decision.trace().size(), 1u);
  EXPECT_EQ(decision.trace()[0].frame_id, 12);
  EXPECT_EQ(decision.trace()[0].t_ns, 600'000'000);
  EXPECT_EQ(decision.trace()[0].frames_since_keyframe, 5);
  EXPECT_EQ(decision.trace()[0].decision.reason, "no");
  EXPECT_EQ(CriteriaHeld(decision.last()), std::vector<std::string>{"criterion1"});
}

}  // namespace
}  // namespace pkslam
