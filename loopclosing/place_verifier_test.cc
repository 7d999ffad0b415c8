#include "loopclosing/place_verifier.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <random>
#include <shared_mutex>
#include <thread>
#include <tuple>

#include "core/bow/bow_test_utils.h"
#include "loopclosing/loop_closing.h"
#include "loopclosing/revisit_fixture.h"
#include "map_model/keyframe_database.h"
#include "map_model/keyframe_database_test_utils.h"
#include "map_model/map_editor.h"

namespace pkslam {
namespace {

using testing::CentreError;
using testing::kKeyFrames;
using testing::RevisitTest;

TEST_F(RevisitTest, VerifiesTheRevisitAndRecoversTheTruePose) {
  const auto second = Revisit(atlas_.current_map(), scene_);
  Finish(second);
  auto lock = MapReader(atlas_).Lock();
  const int q = kKeyFrames / 2;
  const auto region = VerifyCandidate(second[q], first_[q].get(), PlaceVerifierOptions{}, 7);
  ASSERT_TRUE(region.has_value());
  EXPECT_GE(region->matches, PlaceVerifierOptions{}.min_refined_matches);
  // The query's pose in the first visit's (true) world.
  const SE3d found = region->query_camera_from_world.ToSE3ScaledTranslation();
  EXPECT_LT((found.Inverse().translation() - poses_[q].Inverse().translation()).norm(), 0.01);
  EXPECT_LT((found.so3() * poses_[q].so3().Inverse()).Log().norm(), 0.005);
  EXPECT_NEAR(region->query_camera_from_world.scale(), 1.0, 1e-12);  // stereo: SE3
  // Its covisibles agree.
  EXPECT_GE(ConfirmByCovisibles(*region, 5, PlaceVerifierOptions{}), 2);
}

TEST_F(RevisitTest, RejectsTheSameLooksInADifferentGeometry) {
  // Repetitive texture: the same descriptors at shuffled places. BoW finds plenty of matches;
  // no rigid motion explains them.
  testing::SyntheticScene shuffled = scene_;
  std::mt19937_64 rng(3);
  std::shuffle(shuffled.points_world.begin(), shuffled.points_world.end(), rng);
  const auto second = Revisit(atlas_.current_map(), shuffled);
  Finish(second);
  auto lock = MapReader(atlas_).Lock();
  for (int q = 0; q < kKeyFrames; ++q) {
    for (const auto& candidate : first_) {
      EXPECT_FALSE(VerifyCandidate(second[q], candidate.get(), PlaceVerifierOptions{}, 7))
          << "query " << q << " candidate " << candidate->id();
    }
  }
}

// The whole LoopClosing pipeline on the same data: the second visit is detected as a loop
// (same map) and corrected, or merged (other map) and moved into the first visit's map; either
// way the second visit's keyframes end near their true poses. Threaded mode runs the loop and
// global-BA threads while a reader (standing in for tracking) reads the map under the shared
// lock and a fake local mapping answers the pause handshake.
class LoopClosingRevisitTest : public RevisitTest,
                               public ::testing::WithParamInterface<std::tuple<bool, bool>> {};

TEST_P(LoopClosingRevisitTest, ClosesTheLoopOrMergesTheMaps) {
  const auto [merge, synchronous] = GetParam();
  Map* first_map = atlas_.current_map();
  Map* second_map = first_map;
  if (merge) {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    second_map = atlas_.CreateNewMap(lock);
  }
  const auto second = Revisit(second_map, scene_);
  Finish(second);
  {
    auto lock = MapReader(atlas_).Lock();
    EXPECT_GT(CentreError(*second.back(), poses_.back()), 0.1);  // drifted before
  }
  std::atomic<bool> stop_requested{false};
  std::atomic<int> pauses{0};
  MappingControl control;
  control.request_stop = [&] {
    stop_requested = true;
    ++pauses;
  };
  control.is_stopped = [&] { return stop_requested.load(); };
  control.release = [&] { stop_requested = false; };
  LoopClosingOptions options;
  options.synchronous = synchronous;
  LoopClosing loop(&atlas_, Sensor::kStereo, control, options);
  loop.Start();
  std::atomic<bool> done{false};
  std::thread reader([&] {
    double sum = 0;
    while (!done.load()) {
      auto lock = MapReader(atlas_).Lock();
      for (const Map* map : atlas_.maps()) {
        for (const auto& [id, kf] : map->keyframes()) sum += kf->CameraCenter().x();
        for (const auto& [id, mp] : map->map_points()) sum += mp->position().x();
      }
    }
    EXPECT_TRUE(std::isfinite(sum));
  });
  for (const auto& kf : second) loop.InsertKeyFrame(kf);
  loop.Finish();
  done = true;
  reader.join();
  const LoopClosingStats stats = loop.stats();
  ASSERT_EQ(stats.loops.size(), merge ? 0u : 1u);
  ASSERT_EQ(stats.merges.size(), merge ? 1u : 0u);
  EXPECT_EQ(stats.global_ba_finished, 1);
  // Threaded: local mapping was paused for the correction and for the BA write-back.
  EXPECT_EQ(pauses.load(), synchronous ? 0 : 2);
  EXPECT_FALSE(stop_requested.load());  // and released again
  auto lock = MapReader(atlas_).Lock();
  EXPECT_EQ(atlas_.NumMaps(), 1);
  EXPECT_EQ(atlas_.current_map(), first_map);
  for (int k = 0; k < kKeyFrames; ++k) {
    EXPECT_EQ(second[k]->map(), first_map);
    EXPECT_LT(CentreError(*second[k], poses_[k]), 0.01) << "keyframe " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(LoopOrMerge, LoopClosingRevisitTest,
                         ::testing::Combine(::testing::Bool(), ::testing::Bool()));

}  // namespace
}  // namespace pkslam
