// BoW searches (keyframe-frame, keyframe-keyframe), the epipolar search for triangulation and
// the window search of monocular initialisation, against ground-truth correspondences.
#include <gtest/gtest.h>

#include <cmath>
#include <mutex>
#include <random>
#include <set>
#include <shared_mutex>

#include "map_model/map_editor.h"
#include "map_model/matching/matching_test_utils.h"
#include "map_model/matching/orb_matcher.h"

namespace pkslam {
namespace {

using testing::EditFrame;
using testing::FrameOptions;
using testing::MakeBowMap;
using testing::MakeClusteredScene;
using testing::MakeForwardPath;
using testing::MakePosedFrame;
using testing::MakeScene;
using testing::MakeStereoRig;
using testing::SceneIndexOf;
using testing::TrainSceneVocabulary;

// Gives 1 keypoint in 7 a random orientation at least 24 degrees off the true one.
std::vector<std::uint8_t> RotateSome(FrameFeatures* f, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> off(24.f, 336.f);
  std::vector<std::uint8_t> rotated(f->keypoints.size(), 0);
  for (std::size_t i = 0; i < f->keypoints.size(); i += 7) {
    f->keypoints[i].angle = std::fmod(f->keypoints[i].angle + off(rng), 360.f);
    rotated[i] = 1;
  }
  return rotated;
}

class MatcherBowTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = MakeStereoRig();
    scene_ = MakeClusteredScene(1200, 21);
    vocabulary_ = TrainSceneVocabulary(scene_);
    poses_ = MakeForwardPath(4, 0.2, 22);
    FrameOptions o;
    o.pixel_noise = 0.5;
    o.descriptor_bit_flips = 6;
    map_ =
        MakeBowMap(&atlas_, scene_, rig_, {poses_[0], poses_[1], poses_[2]}, o, vocabulary_, true);
    lock_ = MapReader(atlas_).Lock();
  }
  Frame BowFrame(
      int k, std::vector<int>* pok,
      const std::function<void(FrameFeatures*)>& edit = [](FrameFeatures*) {}) const {
    FrameOptions o;
    o.pixel_noise = 1.0;
    o.descriptor_bit_flips = 8;
    o.outlier_fraction = 0.05;
    o.seed = 300 + k;
    const Frame base = MakePosedFrame(scene_, rig_, poses_[k], 3000 + k, o, pok);
    Frame f = EditFrame(base, edit);
    f.SetPose(poses_[k]);
    f.ComputeBoW(vocabulary_);
    return f;
  }

  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticScene scene_;
  Vocabulary vocabulary_;
  std::vector<SE3d> poses_;
  testing::SyntheticMap map_;
  MapReadLock lock_;
};

TEST_F(MatcherBowTest, VocabularyGroupsFeatures) {
  const KeyFrame& kf = *map_.keyframes[0];
  EXPECT_GE(kf.feature_vector().size(), 12u);
  EXPECT_EQ(kf.feature_vector().FeatureCount(), static_cast<std::size_t>(kf.size()));
}

TEST_F(MatcherBowTest, KeyFrameToFrameRecoversTrueMatches) {
  std::vector<int> pok;
  const Frame frame = BowFrame(3, &pok);
  const KeyFrame& kf = *map_.keyframes[2];
  std::vector<MapPointPtr> matches;
  const int n = OrbMatcher(0.75).SearchByBoW(kf, frame, &matches);
  ASSERT_EQ(matches.size(), static_cast<std::size_t>(frame.size()));
  int correct = 0;
  int wrong = 0;
  int findable = 0;
  for (int i = 0; i < frame.size(); ++i) {
    const MapPointPtr& truth = map_.point_of_scene_index[pok[i]];
    findable += truth && truth->IsInKeyFrame(&kf);
    if (!matches[i]) continue;
    (matches[i] == truth ? correct : wrong)++;
  }
  EXPECT_EQ(n, correct + wrong);
  RecordProperty("correct", correct);
  RecordProperty("wrong", wrong);
  RecordProperty("findable", findable);
  EXPECT_GT(correct, 0.85 * findable) << findable;
  EXPECT_LE(wrong, 0.01 * n);
}

TEST_F(MatcherBowTest, KeyFrameToFrameRotationAndRatioChecks) {
  std::vector<int> pok;
  std::vector<std::uint8_t> rotated;
  std::vector<int> duplicated;
  const Frame frame = BowFrame(3, &pok, [&](FrameFeatures* f) {
    rotated = RotateSome(f, 7);
    // Exact duplicates (same descriptor and node) of keypoints 3, 10, 17, ...
    const std::size_t n = f->keypoints.size();
    for (std::size_t i = 3; i < n; i += 7) {
      f->keypoints.push_back(f->keypoints[i]);
      f->descriptors.push_back(f->descriptors[i]);
      f->right_u.push_back(f->right_u[i]);
      f->depth.push_back(f->depth[i]);
      duplicated.push_back(static_cast<int>(i));
    }
  });
  const KeyFrame& kf = *map_.keyframes[2];
  std::vector<MapPointPtr> checked;
  std::vector<MapPointPtr> unchecked;
  const int n = OrbMatcher(0.75, true).SearchByBoW(kf, frame, &checked);
  OrbMatcher(0.75, false).SearchByBoW(kf, frame, &unchecked);
  int rotated_unchecked = 0;
  for (std::size_t i = 0; i < rotated.size(); ++i) {
    if (!rotated[i]) continue;
    EXPECT_EQ(checked[i], nullptr) << i;
    rotated_unchecked += unchecked[i] != nullptr;
  }
  EXPECT_GT(rotated_unchecked, 30);
  EXPECT_GT(n, 300);
  std::size_t original_size = rotated.size();
  for (std::size_t k = 0; k < duplicated.size(); ++k) {
    EXPECT_EQ(checked[duplicated[k]], nullptr);
    EXPECT_EQ(checked[original_size + k], nullptr);
  }
  // Without the ratio test, duplicates match.
  std::vector<MapPointPtr> no_ratio;
  OrbMatcher(1.0, false).SearchByBoW(kf, frame, &no_ratio);
  int matched = 0;
  for (std::size_t k = 0; k < duplicated.size(); ++k) {
    matched += no_ratio[duplicated[k]] || no_ratio[original_size + k];
  }
  EXPECT_GT(matched, static_cast<int>(duplicated.size()) / 2);
}

TEST_F(MatcherBowTest, KeyFrameToKeyFrameAcrossTwoMaps) {
  // A second map of the same place (other noise): loop detection pairs its points with ours.
  lock_.unlock();
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    atlas_.CreateNewMap(lock);
  }
  FrameOptions o;
  o.pixel_noise = 0.5;
  o.descriptor_bit_flips = 6;
  o.seed = 77;
  const testing::SyntheticMap map_b =
      MakeBowMap(&atlas_, scene_, rig_, {poses_[1], poses_[3]}, o, vocabulary_, true);
  lock_.lock();
  const KeyFrame& kf1 = *map_.keyframes[2];
  const KeyFrame& kf2 = *map_b.keyframes[1];
  const auto scene_of_b = SceneIndexOf(map_b);
  std::vector<MapPointPtr> matches12;
  const int n = OrbMatcher(0.75).SearchByBoW(kf1, kf2, &matches12);
  ASSERT_EQ(matches12.size(), static_cast<std::size_t>(kf1.size()));
  int correct = 0;
  int wrong = 0;
  int findable = 0;
  std::set<const MapPoint*> used;
  for (int i1 = 0; i1 < kf1.size(); ++i1) {
    const int scene_index = map_.keypoint_points[2][i1];
    const MapPointPtr& b_point = map_b.point_of_scene_index[scene_index];
    findable += kf1.map_point(i1) && b_point && b_point->IsInKeyFrame(&kf2);
    if (!matches12[i1]) continue;
    EXPECT_TRUE(used.insert(matches12[i1].get()).second);
    (scene_of_b.at(matches12[i1].get()) == scene_index ? correct : wrong)++;
  }
  EXPECT_EQ(n, correct + wrong);
  RecordProperty("correct", correct);
  RecordProperty("wrong", wrong);
  RecordProperty("findable", findable);
  EXPECT_GT(correct, 0.85 * findable) << findable;
  EXPECT_LE(wrong, 0.01 * n);
}

TEST(MatcherInitialization, WindowSearchMatchesLevelZeroOneToOne) {
  const auto rig = MakeStereoRig(Sensor::kMonocular);
  const auto scene = MakeScene(2000, 31);
  const auto poses = MakeForwardPath(2, 0.2, 32);
  FrameOptions o;
  o.stereo = false;
  o.pixel_noise = 0.5;
  o.descriptor_bit_flips = 8;
  std::vector<int> pok1;
  std::vector<int> pok2;
  const Frame f1 = MakePosedFrame(scene, rig, poses[0], 0, o, &pok1);
  o.seed = 2;
  o.outlier_fraction = 0.05;
  std::vector<std::uint8_t> rotated;
  const Frame f2 = EditFrame(MakePosedFrame(scene, rig, poses[1], 1, o, &pok2),
                             [&](FrameFeatures* f) { rotated = RotateSome(f, 3); });
  std::vector<int> keypoint_of_scene(scene.points_world.size(), -1);
  for (int i2 = 0; i2 < f2.size(); ++i2) keypoint_of_scene[pok2[i2]] = i2;

  std::vector<cv::Point2f> prev(f1.size());
  for (int i = 0; i < f1.size(); ++i) prev[i] = f1.keypoints_undistorted()[i].pt;
  std::vector<int> m12;
  const int n = OrbMatcher(0.9).SearchForInitialization(f1, f2, &prev, &m12, 100);
  int correct = 0;
  int wrong = 0;
  int findable = 0;
  std::set<int> used;
  for (int i1 = 0; i1 < f1.size(); ++i1) {
    const int i2_true = keypoint_of_scene[pok1[i1]];
    const bool level0 = f1.keypoints()[i1].octave == 0;
    findable += level0 && i2_true >= 0 && !rotated[i2_true];
    const int i2 = m12[i1];
    if (i2 < 0) {
      EXPECT_EQ(prev[i1], f1.keypoints_undistorted()[i1].pt);
      continue;
    }
    EXPECT_TRUE(level0);
    EXPECT_FALSE(rotated[i2]) << i2;
    EXPECT_TRUE(used.insert(i2).second);
    EXPECT_EQ(prev[i1], f2.keypoints_undistorted()[i2].pt);
    (i2 == i2_true ? correct : wrong)++;
  }
  EXPECT_EQ(n, correct + wrong);
  RecordProperty("correct", correct);
  RecordProperty("wrong", wrong);
  RecordProperty("findable", findable);
  EXPECT_GT(correct, 0.85 * findable) << findable;
  EXPECT_LE(wrong, 0.01 * n);
}

TEST(MatcherInitialization, BetterClaimOnAKeypointWins) {
  const auto rig = MakeStereoRig(Sensor::kMonocular);
  const auto scene = MakeScene(800, 41);
  const auto poses = MakeForwardPath(2, 0.1, 42);
  FrameOptions o;
  o.stereo = false;
  std::vector<int> pok1;
  std::vector<int> pok2;
  const Frame f2 = MakePosedFrame(scene, rig, poses[1], 1, o, &pok2);
  // f1: level-0 keypoints get 30 flipped bits; an exact copy of each is appended, so the later,
  // better claim must take the keypoint of f2 from the earlier one.
  std::mt19937 rng(4);
  std::uniform_int_distribution<int> bit(0, 255);
  std::vector<std::pair<int, int>> pairs;  // (worse original, better copy)
  const Frame f1 =
      EditFrame(MakePosedFrame(scene, rig, poses[0], 0, o, &pok1), [&](FrameFeatures* f) {
        const std::size_t n = f->keypoints.size();
        for (std::size_t i = 0; i < n; ++i) {
          if (f->keypoints[i].octave != 0) continue;
          f->keypoints.push_back(f->keypoints[i]);
          f->descriptors.push_back(f->descriptors[i]);
          pairs.emplace_back(static_cast<int>(i), static_cast<int>(f->keypoints.size() - 1));
          pok1.push_back(pok1[i]);
          std::set<int> bits;
          while (bits.size() < 30) bits.insert(bit(rng));
          for (int b : bits)
            f->descriptors[i].bytes[b / 8] ^= static_cast<std::uint8_t>(1u << (b % 8));
        }
      });
  ASSERT_GT(pairs.size(), 50u);
  std::vector<cv::Point2f> prev(f1.size());
  for (int i = 0; i < f1.size(); ++i) prev[i] = f1.keypoints_undistorted()[i].pt;
  std::vector<int> m12;
  OrbMatcher(0.9).SearchForInitialization(f1, f2, &prev, &m12, 100);
  int copies_matched = 0;
  for (const auto& [worse, better] : pairs) {
    EXPECT_EQ(m12[worse], -1) << worse;
    copies_matched += m12[better] >= 0 && pok2[m12[better]] == pok1[better];
  }
  EXPECT_GT(copies_matched, 0.9 * pairs.size());
}

}  // namespace
}  // namespace pkslam
