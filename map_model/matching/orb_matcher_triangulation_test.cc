// SearchForTriangulation: BoW-node candidates gated by the epipolar constraint, the epipole
// and existing map points.
#include <gtest/gtest.h>

#include <mutex>
#include <set>

#include "map_model/map_editor.h"
#include "map_model/matching/matching_test_utils.h"
#include "map_model/matching/orb_matcher.h"

namespace pkslam {
namespace {

using testing::EditFrame;
using testing::FrameOptions;
using testing::MakeClusteredScene;
using testing::MakeForwardPath;
using testing::MakePosedFrame;
using testing::MakeStereoRig;
using testing::TrainSceneVocabulary;

class MatcherTriangulationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = MakeStereoRig(Sensor::kMonocular);
    scene_ = MakeClusteredScene(1200, 51);
    vocabulary_ = TrainSceneVocabulary(scene_);
    poses_ = MakeForwardPath(3, 0.2, 52);
  }
  // A keyframe (no map points) from the frame at `pose`, after `edit`.
  KeyFramePtr MakeKeyFrame(
      const SE3d& pose, std::uint64_t seed, bool stereo, std::vector<int>* pok,
      const std::function<void(FrameFeatures*)>& edit = [](FrameFeatures*) {}) {
    FrameOptions o;
    o.stereo = stereo;
    o.pixel_noise = 0.3;
    o.descriptor_bit_flips = 6;
    o.seed = seed;
    Frame f = EditFrame(MakePosedFrame(scene_, rig_, pose, atlas_.NextFrameId(), o, pok), edit);
    f.SetPose(pose);
    f.ComputeBoW(vocabulary_);
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    auto kf = std::make_shared<KeyFrame>(atlas_.NextKeyFrameId(), f, atlas_.current_map());
    atlas_.current_map()->AddKeyFrame(lock, kf);
    return kf;
  }
  // Projection of kf1's centre into kf2 (the epipole) and of a world point.
  Eigen::Vector2d Project(const KeyFrame& kf, const Eigen::Vector3d& p_world) const {
    const Eigen::Vector3d pc = kf.camera_from_world() * p_world;
    return {rig_->fx * pc.x() / pc.z() + rig_->cx, rig_->fy * pc.y() / pc.z() + rig_->cy};
  }

  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticScene scene_;
  Vocabulary vocabulary_;
  std::vector<SE3d> poses_;
};

TEST_F(MatcherTriangulationTest, PairsAreCorrectAndOneToOne) {
  std::vector<int> pok1;
  std::vector<int> pok2;
  const auto kf1 = MakeKeyFrame(poses_[0], 1, false, &pok1);
  const auto kf2 = MakeKeyFrame(poses_[2], 2, false, &pok2);
  std::set<int> in2(pok2.begin(), pok2.end());
  int common = 0;
  for (int p : pok1) common += in2.count(p) > 0;
  auto lock = MapReader(atlas_).Lock();
  const auto pairs = OrbMatcher(0.6).SearchForTriangulation(*kf1, *kf2);
  int correct = 0;
  std::set<int> used1;
  std::set<int> used2;
  for (const auto& [i1, i2] : pairs) {
    EXPECT_TRUE(used1.insert(i1).second);
    EXPECT_TRUE(used2.insert(i2).second);
    correct += pok1[i1] == pok2[i2];
  }
  RecordProperty("correct", correct);
  RecordProperty("pairs", static_cast<int>(pairs.size()));
  RecordProperty("common", common);
  EXPECT_GT(correct, 0.85 * common) << common;
  EXPECT_GE(correct, 0.98 * static_cast<double>(pairs.size()));
  // Keypoints that already have a map point are not paired.
  {
    auto write = MapEditor(&atlas_).WriteLater(MapEdit::kFixture);
    lock.unlock();
    write.lock();
    for (int i = 0; i < kf1->size(); i += 2) {
      kf1->AddMapPoint(write,
                       std::make_shared<MapPoint>(atlas_.NextMapPointId(), Eigen::Vector3d(0, 0, 5),
                                                  kf1.get(), nullptr),
                       i);
    }
  }
  lock.lock();
  const auto pairs_half = OrbMatcher(0.6).SearchForTriangulation(*kf1, *kf2);
  EXPECT_GT(pairs_half.size(), pairs.size() / 3);
  for (const auto& [i1, i2] : pairs_half) EXPECT_EQ(i1 % 2, 1);
}

TEST_F(MatcherTriangulationTest, EpipolarConstraintRejectsOffLineKeypoints) {
  std::vector<int> pok1;
  std::vector<int> pok2;
  const auto kf1 = MakeKeyFrame(poses_[0], 1, false, &pok1);
  // In kf2, move every third keypoint 4 sigma across its epipolar line and every third + 1
  // keypoint 4 sigma along it.
  const SE3d& pose2 = poses_[2];
  const Eigen::Vector3d c1_in_2 = pose2 * kf1->CameraCenter();
  const Eigen::Vector2d epipole(rig_->fx * c1_in_2.x() / c1_in_2.z() + rig_->cx,
                                rig_->fy * c1_in_2.y() / c1_in_2.z() + rig_->cy);
  std::vector<int> across;
  std::vector<int> along;
  const auto kf2 = MakeKeyFrame(pose2, 2, false, &pok2, [&](FrameFeatures* f) {
    for (std::size_t i = 0; i < f->keypoints.size(); ++i) {
      cv::KeyPoint& kp = f->keypoints[i];
      const Eigen::Vector2d x(kp.pt.x, kp.pt.y);
      const Eigen::Vector2d dir = (x - epipole).normalized();
      const Eigen::Vector2d normal(-dir.y(), dir.x());
      const double shift = 4.0 * rig_->pyramid.scale[kp.octave];
      Eigen::Vector2d moved = x;
      if (i % 3 == 0) {
        moved += shift * normal;
        across.push_back(static_cast<int>(i));
      } else if (i % 3 == 1) {
        moved += shift * dir;
        along.push_back(static_cast<int>(i));
      }
      kp.pt = cv::Point2f(static_cast<float>(moved.x()), static_cast<float>(moved.y()));
    }
  });
  auto lock = MapReader(atlas_).Lock();
  const auto pairs = OrbMatcher(0.6).SearchForTriangulation(*kf1, *kf2);
  std::set<int> matched2;
  for (const auto& [i1, i2] : pairs) matched2.insert(i2);
  int across_matched = 0;
  int along_correct = 0;
  for (int i : across) across_matched += matched2.count(i) > 0;
  for (const auto& [i1, i2] : pairs) {
    if (i2 % 3 == 1 && pok1[i1] == pok2[i2]) ++along_correct;
  }
  EXPECT_EQ(across_matched, 0);
  EXPECT_GT(along_correct, 0.7 * along.size());
}

TEST_F(MatcherTriangulationTest, KeypointsNearTheEpipoleAreSkippedWithoutStereo) {
  // Pure forward motion: the epipole is the principal point in both images. Points near the
  // optical axis project within a few pixels of it.
  const int first_axis_point = static_cast<int>(scene_.points_world.size());
  for (int k = 0; k < 6; ++k) {
    scene_.points_world.emplace_back(0.01 * (k - 3), 0.008 * (k % 2), 4.0 + 0.3 * k);
    // A new descriptor in the same cluster: 40 bits away from an existing one.
    Descriptor d = scene_.descriptors[k * 97];
    for (int b = 0; b < 40; ++b) {
      const int bit = (b * 37 + k * 11) % 256;
      d.bytes[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    }
    scene_.descriptors.push_back(d);
    scene_.octaves.push_back(0);
  }
  const SE3d pose1;
  const SE3d pose2(SO3d(), Eigen::Vector3d(0, 0, -0.4));
  for (const bool stereo : {false, true}) {
    std::vector<int> pok1;
    std::vector<int> pok2;
    const auto kf1 = MakeKeyFrame(pose1, 1, stereo, &pok1);
    const auto kf2 = MakeKeyFrame(pose2, 2, stereo, &pok2);
    auto lock = MapReader(atlas_).Lock();
    const auto pairs = OrbMatcher(0.6).SearchForTriangulation(*kf1, *kf2);
    int axis = 0;
    int correct = 0;
    for (const auto& [i1, i2] : pairs) {
      correct += pok1[i1] == pok2[i2];
      axis += pok1[i1] >= first_axis_point && pok1[i1] == pok2[i2];
    }
    EXPECT_GT(correct, 200) << stereo;
    // Stereo keypoints have depth: near-epipole pairs are fine to triangulate.
    if (stereo) {
      EXPECT_GE(axis, 4);
    } else {
      EXPECT_EQ(axis, 0);
    }
  }
}

TEST_F(MatcherTriangulationTest, OnlyStereoPairsKeypointsWithDepth) {
  std::vector<int> pok1;
  std::vector<int> pok2;
  // Half of kf1's keypoints lose their depth.
  const auto kf1 = MakeKeyFrame(poses_[0], 1, true, &pok1, [](FrameFeatures* f) {
    for (std::size_t i = 0; i < f->keypoints.size(); i += 2) {
      f->right_u[i] = -1;
      f->depth[i] = -1;
    }
  });
  const auto kf2 = MakeKeyFrame(poses_[1], 2, true, &pok2);
  auto lock = MapReader(atlas_).Lock();
  const auto all = OrbMatcher(0.6).SearchForTriangulation(*kf1, *kf2, false);
  const auto stereo = OrbMatcher(0.6).SearchForTriangulation(*kf1, *kf2, true);
  int all_without_depth = 0;
  for (const auto& [i1, i2] : all) all_without_depth += i1 % 2 == 0;
  EXPECT_GT(all_without_depth, 100);
  EXPECT_GT(stereo.size(), 100u);
  for (const auto& [i1, i2] : stereo) {
    EXPECT_EQ(i1 % 2, 1);
    EXPECT_GE(kf2->right_u()[i2], 0);
  }
}

}  // namespace
}  // namespace pkslam
