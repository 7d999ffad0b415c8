#include "map_model/keyframe_database.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <mutex>

#include "core/bow/bow_test_utils.h"
#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/keyframe_database_test_utils.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

using testing::AddKeyFrames;
using testing::MakeFrame;
using testing::MakeScene;
using testing::MakeStereoRig;
using testing::Strip;

class KeyFrameDatabaseTest : public ::testing::Test {
 protected:
  KeyFrameDatabaseTest()
      : vocabulary_(testing::MakeRandomVocabulary(10, 4, 5)),
        rig_(MakeStereoRig()),
        scene_(MakeScene(4000, 11, 30.0, 2.5, 4.0, 8.0)) {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    map_a_ = atlas_.current_map();
    map_b_ = atlas_.CreateNewMap(lock);
    atlas_.SetCurrentMap(lock, map_a_);
  }

  Frame QueryFrame(const SE3d& pose) {
    testing::FrameOptions options;
    options.descriptor_bit_flips = 2;
    options.seed = 999;
    std::vector<int> kp_points;
    Frame f = MakeFrame(scene_, rig_, pose, 12345, 0, options, &kp_points);
    f.ComputeBoW(vocabulary_);
    return f;
  }

  Vocabulary vocabulary_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticScene scene_;
  Atlas atlas_;
  Map* map_a_ = nullptr;
  Map* map_b_ = nullptr;
};

TEST_F(KeyFrameDatabaseTest, RelocalisationFindsTheKeyFramesOfThePlace) {
  // 20 keyframes 1.2 m apart along a 60 m wall: a frame at keyframe 12's place must return
  // keyframe 12 (or an immediate neighbour) first and nothing far away.
  const auto poses = Strip(-24.0, 1.2, 20);
  const auto kfs = AddKeyFrames(&atlas_, map_a_, scene_, rig_, poses, vocabulary_, 1);
  KeyFrameDatabase db(vocabulary_);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  for (const auto& kf : kfs) db.Add(lock, kf.get());
  ASSERT_EQ(db.size(), 20u);

  const Frame query =
      QueryFrame(SE3d(SO3d(), Eigen::Vector3d(-24.0 + 1.2 * 12 + 0.1, 0.05, 0)).Inverse());
  const auto candidates = db.DetectRelocalisationCandidates(query, map_a_);
  ASSERT_FALSE(candidates.empty());
  EXPECT_EQ(candidates.front().keyframe, kfs[12].get());
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const auto index = candidates[i].keyframe->id() - kfs.front()->id();
    EXPECT_NEAR(static_cast<double>(index), 12.0, 2.0) << "candidate " << i;
    EXPECT_GT(candidates[i].score, 0.0);
    EXPECT_GE(candidates[i].group_score, candidates[i].score);
    if (i > 0) {
      EXPECT_LE(candidates[i].group_score, candidates[i - 1].group_score);
    }
  }
  // The map filter: nothing of map A is a candidate in map B.
  EXPECT_TRUE(db.DetectRelocalisationCandidates(query, map_b_).empty());
  EXPECT_FALSE(db.DetectRelocalisationCandidates(query, nullptr).empty());
}

TEST_F(KeyFrameDatabaseTest, LoopAndMergeCandidatesExcludeConnectedKeyFrames) {
  // Map A: a first pass along the wall and a later revisit of its middle (its own points, so
  // not connected to the first pass). Map B: another session over the same middle part.
  const auto first =
      AddKeyFrames(&atlas_, map_a_, scene_, rig_, Strip(-24.0, 1.2, 20), vocabulary_, 1);
  const auto revisit =
      AddKeyFrames(&atlas_, map_a_, scene_, rig_, Strip(-10.0, 1.2, 6, 0.1), vocabulary_, 100);
  const auto other =
      AddKeyFrames(&atlas_, map_b_, scene_, rig_, Strip(-10.5, 1.2, 6, -0.1), vocabulary_, 200);
  KeyFrameDatabase db(vocabulary_);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  for (const auto* list : {&first, &revisit, &other}) {
    for (const auto& kf : *list) db.Add(lock, kf.get());
  }
  const KeyFrame* query = revisit[3].get();  // at x = -6.4, i.e. first-pass keyframe ~14.7
  const auto result = db.DetectLoopAndMergeCandidates(query, 3);
  ASSERT_FALSE(result.loop.empty());
  ASSERT_FALSE(result.merge.empty());
  EXPECT_LE(result.loop.size(), 3u);
  EXPECT_LE(result.merge.size(), 3u);
  const auto connected = query->ConnectedKeyFrames();
  for (const auto& c : result.loop) {
    EXPECT_EQ(c.keyframe->map(), map_a_);
    EXPECT_NE(c.keyframe, query);
    EXPECT_EQ(std::count(connected.begin(), connected.end(), c.keyframe), 0);
    // Only first-pass keyframes near x = -6.4 (indices 13..16) qualify.
    const auto index = c.keyframe->id() - first.front()->id();
    EXPECT_GE(index, 12);
    EXPECT_LE(index, 17);
  }
  EXPECT_NEAR(static_cast<double>(result.loop.front().keyframe->id() - first.front()->id()), 14.7,
              1.0);
  for (const auto& c : result.merge) EXPECT_EQ(c.keyframe->map(), map_b_);
  // Every revisit keyframe is connected to the query: none of them is a candidate.
  for (const auto& kf : revisit) {
    for (const auto& c : result.loop) EXPECT_NE(c.keyframe, kf.get());
  }
}

TEST_F(KeyFrameDatabaseTest, EraseWorksAfterRetirementAndClearIsPerMap) {
  const auto a = AddKeyFrames(&atlas_, map_a_, scene_, rig_, Strip(-24.0, 1.2, 20), vocabulary_, 1);
  const auto b = AddKeyFrames(&atlas_, map_b_, scene_, rig_, Strip(-24.0, 1.2, 5), vocabulary_, 7);
  KeyFrameDatabase db(vocabulary_);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  for (const auto& kf : a) db.Add(lock, kf.get());
  for (const auto& kf : b) db.Add(lock, kf.get());
  EXPECT_EQ(db.size(), 25u);

  // Retire keyframe 12: its BoW is released, erasing must still unlink it everywhere.
  KeyFrame* retired = a[12].get();
  retired->SetBad(lock);
  ASSERT_TRUE(retired->IsBad());
  ASSERT_TRUE(retired->bow().empty());
  db.Erase(lock, retired);
  EXPECT_FALSE(db.Contains(retired));
  EXPECT_EQ(db.size(), 24u);
  const Frame query = QueryFrame(SE3d(SO3d(), Eigen::Vector3d(-24.0 + 1.2 * 12, 0, 0)).Inverse());
  for (const auto& c : db.DetectRelocalisationCandidates(query, map_a_)) {
    EXPECT_NE(c.keyframe, retired);
  }
  db.Erase(lock, retired);  // unknown now: no-op
  EXPECT_EQ(db.size(), 24u);

  db.Clear(map_b_);
  EXPECT_EQ(db.size(), 19u);
  for (const auto& kf : b) EXPECT_FALSE(db.Contains(kf.get()));
  EXPECT_TRUE(db.DetectRelocalisationCandidates(query, map_b_).empty());
  EXPECT_FALSE(db.DetectRelocalisationCandidates(query, map_a_).empty());
  db.Clear();
  EXPECT_EQ(db.size(), 0u);
  EXPECT_TRUE(db.DetectRelocalisationCandidates(query, nullptr).empty());
}

TEST_F(KeyFrameDatabaseTest, ResultsDoNotDependOnInsertionOrder) {
  const auto kfs =
      AddKeyFrames(&atlas_, map_a_, scene_, rig_, Strip(-24.0, 1.2, 20), vocabulary_, 1);
  KeyFrameDatabase forward(vocabulary_);
  KeyFrameDatabase backward(vocabulary_);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  for (const auto& kf : kfs) forward.Add(lock, kf.get());
  for (auto it = kfs.rbegin(); it != kfs.rend(); ++it) backward.Add(lock, it->get());
  for (int place : {3, 9, 15}) {
    const Frame query =
        QueryFrame(SE3d(SO3d(), Eigen::Vector3d(-24.0 + 1.2 * place + 0.3, 0, 0)).Inverse());
    const auto f = forward.DetectRelocalisationCandidates(query, map_a_);
    const auto b = backward.DetectRelocalisationCandidates(query, map_a_);
    ASSERT_EQ(f.size(), b.size());
    for (std::size_t i = 0; i < f.size(); ++i) {
      EXPECT_EQ(f[i].keyframe, b[i].keyframe);
      EXPECT_EQ(f[i].group_score, b[i].group_score);
    }
    const auto lf =
        forward.DetectLoopAndMergeCandidates(kfs[static_cast<std::size_t>(place)].get());
    const auto lb =
        backward.DetectLoopAndMergeCandidates(kfs[static_cast<std::size_t>(place)].get());
    ASSERT_EQ(lf.loop.size(), lb.loop.size());
    for (std::size_t i = 0; i < lf.loop.size(); ++i)
      EXPECT_EQ(lf.loop[i].keyframe, lb.loop[i].keyframe);
  }
}

TEST_F(KeyFrameDatabaseTest, AddAndEraseRefuseToRunWithoutTheWriteLock) {
  const auto kfs =
      AddKeyFrames(&atlas_, map_a_, scene_, rig_, Strip(-24.0, 1.2, 2), vocabulary_, 1);
  KeyFrameDatabase db(vocabulary_);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  db.Add(lock, kfs[0].get());
  lock.unlock();
  EXPECT_THROW(db.Add(lock, kfs[1].get()), Error);
  EXPECT_THROW(db.Erase(lock, kfs[0].get()), Error);
  EXPECT_EQ(db.size(), 1u);
  EXPECT_TRUE(db.Contains(kfs[0].get()));
  EXPECT_FALSE(db.Contains(kfs[1].get()));
}

TEST_F(KeyFrameDatabaseTest, RejectsWordsOutsideTheVocabularyAndBadOptions) {
  Vocabulary small = testing::MakeRandomVocabulary(2, 2, 3);  // 4 words
  const auto kfs =
      AddKeyFrames(&atlas_, map_a_, scene_, rig_, Strip(-24.0, 1.2, 2), vocabulary_, 1);
  KeyFrameDatabase db(small);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  EXPECT_THROW(db.Add(lock, kfs[0].get()), Error);
  KeyFrameDatabaseOptions options;
  options.min_common_words_ratio = 1.5;
  EXPECT_THROW(KeyFrameDatabase(vocabulary_, options), OptionError);
}

}  // namespace
}  // namespace pkslam
