// Search-by-projection flavours (local map, motion model, relocalisation) and the rotation
// histogram, against the synthetic map's ground-truth correspondences.
#include <gtest/gtest.h>

#include <algorithm>
#include <mutex>
#include <random>
#include <set>
#include <shared_mutex>

#include "map_model/map_editor.h"
#include "map_model/matching/matching_test_utils.h"
#include "map_model/matching/orb_matcher.h"
#include "map_model/matching/orb_matcher_internal.h"

namespace pkslam {
namespace {

using testing::EditFrame;
using testing::FrameOptions;
using testing::MakeForwardPath;
using testing::MakeMap;
using testing::MakePosedFrame;
using testing::MakeScene;
using testing::MakeStereoRig;
using testing::ProjectMapPoints;

TEST(MatcherRotationHistogram, BinsWrapAroundAndRoundToTwelveDegrees) {
  using matching_detail::RotationBin;
  EXPECT_EQ(RotationBin(45.f, 45.f), 0);
  EXPECT_EQ(RotationBin(50.f, 45.f), 0);   // +5 deg rounds to bin 0
  EXPECT_EQ(RotationBin(52.f, 45.f), 1);   // +7 deg rounds to bin 1
  EXPECT_EQ(RotationBin(40.f, 45.f), 0);   // -5 deg = 355 deg -> bin 30 = bin 0
  EXPECT_EQ(RotationBin(30.f, 45.f), 29);  // -15 deg = 345 deg
  EXPECT_EQ(RotationBin(135.f, 45.f), 8);  // 90 deg -> 7.5 rounds to 8
  EXPECT_EQ(RotationBin(359.f, 0.f), 0);
  EXPECT_EQ(RotationBin(0.f, 359.f), 0);
  EXPECT_EQ(RotationBin(185.f, 5.f), 15);
}

TEST(MatcherRotationHistogram, ThreeMaximaDropsMinorPeaks) {
  std::vector<std::vector<int>> h(kRotationHistogramBins);
  EXPECT_EQ(OrbMatcher::ThreeMaxima(h), (std::array<int, 3>{-1, -1, -1}));
  h[4].assign(100, 0);
  h[7].assign(30, 0);
  h[20].assign(12, 0);
  h[21].assign(9, 0);  // below 10% of the main peak
  EXPECT_EQ(OrbMatcher::ThreeMaxima(h), (std::array<int, 3>{4, 7, 20}));
  h[20].assign(5, 0);
  EXPECT_EQ(OrbMatcher::ThreeMaxima(h), (std::array<int, 3>{4, 7, -1}));
  h[7].assign(9, 0);
  EXPECT_EQ(OrbMatcher::ThreeMaxima(h), (std::array<int, 3>{4, -1, -1}));
  h[29].assign(150, 0);  // a new main peak demotes the others
  EXPECT_EQ(OrbMatcher::ThreeMaxima(h), (std::array<int, 3>{29, 4, -1}));
}

struct Score {
  int correct = 0;
  int wrong = 0;
};

// Scores frame matches against the scene index of each keypoint.
Score ScoreFrame(const Frame& frame, const std::vector<int>& point_of_keypoint,
                 const std::vector<MapPointPtr>& point_of_scene_index) {
  Score s;
  for (int i = 0; i < frame.size(); ++i) {
    if (!frame.map_points[i]) continue;
    if (frame.map_points[i] == point_of_scene_index[point_of_keypoint[i]]) {
      ++s.correct;
    } else {
      ++s.wrong;
    }
  }
  return s;
}

// Keypoints whose scene point has a map point (the most a search can find).
int Findable(const std::vector<int>& point_of_keypoint,
             const std::vector<MapPointPtr>& point_of_scene_index) {
  int n = 0;
  for (int p : point_of_keypoint) n += point_of_scene_index[p] != nullptr;
  return n;
}

class MatcherProjectionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = MakeStereoRig();
    scene_ = MakeScene(1500, 11);
    poses_ = MakeForwardPath(5, 0.2, 12);
    map_ = MakeMap(&atlas_, scene_, rig_, {poses_[0], poses_[1], poses_[2]}, {});
    lock_ = MapReader(atlas_).Lock();
    for (const auto& mp : map_.point_of_scene_index) {
      if (mp) points_.push_back(mp);
    }
  }
  // A frame at poses_[k] with noise, appearance change and outliers.
  Frame NoisyFrame(int k, std::vector<int>* pok, double outliers = 0.05) const {
    FrameOptions o;
    o.pixel_noise = 1.0;
    o.descriptor_bit_flips = 12;
    o.outlier_fraction = outliers;
    o.seed = 100 + k;
    return MakePosedFrame(scene_, rig_, poses_[k], 1000 + k, o, pok);
  }

  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticScene scene_;
  std::vector<SE3d> poses_;
  testing::SyntheticMap map_;
  MapReadLock lock_;
  std::vector<MapPointPtr> points_;
};

TEST_F(MatcherProjectionTest, LocalMapSearchRecoversTrueMatches) {
  std::vector<int> pok;
  Frame frame = NoisyFrame(3, &pok);
  const auto projected = ProjectMapPoints(points_, frame);
  ASSERT_GT(projected.size(), 500u);
  const OrbMatcher matcher(0.8);
  const int n = matcher.SearchByProjection(&frame, projected, 1.0);
  const Score s = ScoreFrame(frame, pok, map_.point_of_scene_index);
  EXPECT_EQ(n, s.correct + s.wrong);
  const int findable = Findable(pok, map_.point_of_scene_index);
  RecordProperty("correct", s.correct);
  RecordProperty("wrong", s.wrong);
  RecordProperty("findable", findable);
  EXPECT_GT(s.correct, 0.85 * findable) << findable;
  EXPECT_LT(s.wrong, 0.01 * n);
  // One map point per slot, one slot per map point.
  std::set<const MapPoint*> used;
  for (const auto& mp : frame.map_points) {
    if (mp) {
      EXPECT_TRUE(used.insert(mp.get()).second);
    }
  }
}

// Hard case: descriptors of neighbouring points only ~67 bits apart (well under TH_HIGH),
// heavy appearance change and 10% outliers. Wrong matches appear but stay rare.
TEST(MatcherProjectionHard, SimilarDescriptorsNoiseAndOutliers) {
  Atlas atlas;
  const auto rig = MakeStereoRig();
  const auto scene = testing::MakeClusteredScene(2500, 13);
  const auto poses = MakeForwardPath(5, 0.2, 14);
  FrameOptions o;
  o.pixel_noise = 0.7;
  o.descriptor_bit_flips = 10;
  const auto map = MakeMap(&atlas, scene, rig, {poses[0], poses[1], poses[2]}, o);
  auto lock = MapReader(atlas).Lock();
  std::vector<MapPointPtr> points;
  for (const auto& mp : map.point_of_scene_index) {
    if (mp) points.push_back(mp);
  }
  o.pixel_noise = 1.5;
  o.descriptor_bit_flips = 25;
  o.outlier_fraction = 0.1;
  o.seed = 9;
  std::vector<int> pok;
  Frame frame = MakePosedFrame(scene, rig, poses[3], 500, o, &pok);
  const int n = OrbMatcher(0.8).SearchByProjection(&frame, ProjectMapPoints(points, frame), 3.0);
  const Score s = ScoreFrame(frame, pok, map.point_of_scene_index);
  const int findable = Findable(pok, map.point_of_scene_index);
  RecordProperty("local_correct", s.correct);
  RecordProperty("local_wrong", s.wrong);
  RecordProperty("local_findable", findable);
  EXPECT_EQ(n, s.correct + s.wrong);
  EXPECT_GT(s.correct, 0.75 * findable);
  EXPECT_GT(s.wrong, 0);  // the case is hard enough to produce some
  EXPECT_LT(s.wrong, 0.03 * n);

  // Motion model from the previous frame (ground-truth matched), predicted pose 3 cm off.
  std::vector<int> pok_last;
  o.seed = 10;
  Frame last = MakePosedFrame(scene, rig, poses[2], 499, o, &pok_last);
  for (int i = 0; i < last.size(); ++i) last.map_points[i] = map.point_of_scene_index[pok_last[i]];
  Frame current = MakePosedFrame(scene, rig, poses[3], 500, o, &pok);
  current.SetPose(SE3d(SO3d(), Eigen::Vector3d(0.03, 0.0, -0.01)) * poses[3]);
  const int n_mm = OrbMatcher(0.9).SearchByProjection(&current, last, 7.0, false);
  const Score mm = ScoreFrame(current, pok, map.point_of_scene_index);
  RecordProperty("motion_correct", mm.correct);
  RecordProperty("motion_wrong", mm.wrong);
  EXPECT_EQ(n_mm, mm.correct + mm.wrong);
  EXPECT_GT(mm.correct, 0.6 * findable);
  EXPECT_LT(mm.wrong, 0.03 * n_mm);
}

TEST_F(MatcherProjectionTest, LocalMapSearchRespectsOccupiedSlotsStereoAndFarPoints) {
  std::vector<int> pok;
  Frame base = NoisyFrame(3, &pok, 0.0);
  // Corrupt the right coordinate of the first 50 keypoints with a stereo match.
  std::vector<int> corrupted;
  Frame frame = EditFrame(base, [&](FrameFeatures* f) {
    for (std::size_t i = 0; i < f->right_u.size() && corrupted.size() < 50; ++i) {
      if (f->right_u[i] < 0 || !map_.point_of_scene_index[pok[i]]) continue;
      f->right_u[i] -= 30.0f;
      corrupted.push_back(static_cast<int>(i));
    }
  });
  frame.SetPose(base.camera_from_world());
  // Pre-fill one slot with its true point: it must stay and not be counted.
  int prefilled = -1;
  for (int i = 0; i < frame.size(); ++i) {
    if (map_.point_of_scene_index[pok[i]] &&
        std::find(corrupted.begin(), corrupted.end(), i) == corrupted.end()) {
      prefilled = i;
      break;
    }
  }
  ASSERT_GE(prefilled, 0);
  frame.map_points[prefilled] = map_.point_of_scene_index[pok[prefilled]];
  const auto projected = ProjectMapPoints(points_, frame);
  const OrbMatcher matcher(0.8);
  const int n = matcher.SearchByProjection(&frame, projected, 1.0);
  const Score s = ScoreFrame(frame, pok, map_.point_of_scene_index);
  EXPECT_EQ(n + 1, s.correct + s.wrong);
  for (int i : corrupted) EXPECT_EQ(frame.map_points[i], nullptr) << i;

  // Far points: nothing deeper than 5 m gets matched.
  Frame frame2 = NoisyFrame(3, &pok, 0.0);
  const auto projected2 = ProjectMapPoints(points_, frame2);
  const int n2 = matcher.SearchByProjection(&frame2, projected2, 1.0, 5.0);
  EXPECT_GT(n2, 50);
  for (int i = 0; i < frame2.size(); ++i) {
    if (frame2.map_points[i]) {
      EXPECT_LE((frame2.camera_from_world() * frame2.map_points[i]->position()).z(), 5.0);
    }
  }
}

TEST_F(MatcherProjectionTest, LocalMapRatioTestRejectsAmbiguousDuplicates) {
  std::vector<int> pok;
  Frame base = NoisyFrame(3, &pok, 0.0);
  // Duplicate 40 matchable keypoints 1 px away with the same descriptor and level.
  std::vector<int> duplicated;
  Frame frame = EditFrame(base, [&](FrameFeatures* f) {
    const std::size_t n = f->keypoints.size();
    for (std::size_t i = 0; i < n && duplicated.size() < 40; i += 7) {
      if (!map_.point_of_scene_index[pok[i]]) continue;
      cv::KeyPoint kp = f->keypoints[i];
      kp.pt.x += 1.0f;
      f->keypoints.push_back(kp);
      f->descriptors.push_back(f->descriptors[i]);
      f->right_u.push_back(f->right_u[i] + 1.0f);
      f->depth.push_back(f->depth[i]);
      duplicated.push_back(static_cast<int>(i));
    }
  });
  frame.SetPose(base.camera_from_world());
  const auto projected = ProjectMapPoints(points_, frame);
  OrbMatcher(0.8).SearchByProjection(&frame, projected, 1.0);
  int matched_duplicates = 0;
  for (std::size_t k = 0; k < duplicated.size(); ++k) {
    matched_duplicates += frame.map_points[duplicated[k]] != nullptr;
    matched_duplicates += frame.map_points[base.size() + k] != nullptr;
  }
  EXPECT_EQ(matched_duplicates, 0);
  // Without the ratio test they match.
  Frame frame2 = frame;
  frame2.map_points.assign(frame2.size(), nullptr);
  OrbMatcher(1.0).SearchByProjection(&frame2, projected, 1.0);
  int matched2 = 0;
  for (std::size_t k = 0; k < duplicated.size(); ++k) {
    matched2 += frame2.map_points[duplicated[k]] || frame2.map_points[base.size() + k];
  }
  EXPECT_GT(matched2, 30);
}

// Last frame: matched to the map by ground truth.
Frame LastFrameWithPoints(const Frame& f, const std::vector<int>& pok,
                          const std::vector<MapPointPtr>& points) {
  Frame out = f;
  for (int i = 0; i < out.size(); ++i) out.map_points[i] = points[pok[i]];
  return out;
}

TEST_F(MatcherProjectionTest, MotionModelSearchRecoversTrueMatches) {
  std::vector<int> pok_last;
  std::vector<int> pok;
  const Frame last =
      LastFrameWithPoints(NoisyFrame(2, &pok_last, 0.0), pok_last, map_.point_of_scene_index);
  for (const bool mono : {false, true}) {
    Frame current = NoisyFrame(3, &pok);
    // The predicted pose is off by a few centimetres.
    current.SetPose(SE3d(SO3d(), Eigen::Vector3d(0.02, -0.01, 0.0)) * poses_[3]);
    const int n = OrbMatcher(0.9).SearchByProjection(&current, last, 7.0, mono);
    const Score s = ScoreFrame(current, pok, map_.point_of_scene_index);
    EXPECT_EQ(n, s.correct + s.wrong);
    const int findable = Findable(pok, map_.point_of_scene_index);
    RecordProperty(mono ? "mono_correct" : "stereo_correct", s.correct);
    RecordProperty(mono ? "mono_wrong" : "stereo_wrong", s.wrong);
    RecordProperty(mono ? "mono_findable" : "stereo_findable", findable);
    EXPECT_GT(s.correct, 0.8 * findable) << mono;
    EXPECT_LT(s.wrong, 0.02 * n) << mono;
  }
}

TEST_F(MatcherProjectionTest, MotionModelOctaveWindowFollowsForwardMotion) {
  std::vector<int> pok_last;
  std::vector<int> pok;
  const Frame last =
      LastFrameWithPoints(NoisyFrame(2, &pok_last, 0.0), pok_last, map_.point_of_scene_index);
  // Current frame 0.5 m ahead (more than the 0.11 m baseline) along the optical axis, all its
  // keypoints one octave finer than in the last frame (impossible when approaching).
  const SE3d ahead = SE3d(SO3d(), Eigen::Vector3d(0, 0, -0.5)) * poses_[2];
  FrameOptions o;
  const Frame base = MakePosedFrame(scene_, rig_, ahead, 2000, o, &pok);
  Frame finer = EditFrame(base, [](FrameFeatures* f) {
    for (auto& kp : f->keypoints) kp.octave = std::max(0, kp.octave - 1);
  });
  finer.SetPose(ahead);
  Frame same = base;
  Frame finer_mono = finer;
  const OrbMatcher matcher(0.9);
  const int n_same = matcher.SearchByProjection(&same, last, 7.0, false);
  EXPECT_GT(n_same, 300);
  const int n_finer = matcher.SearchByProjection(&finer, last, 7.0, false);
  // Only points that were at octave 0 already can still match.
  int level0 = 0;
  for (int i = 0; i < base.size(); ++i) level0 += base.keypoints()[i].octave == 0;
  EXPECT_LE(n_finer, level0);
  // Monocular: no octave restriction beyond +-1.
  EXPECT_GT(matcher.SearchByProjection(&finer_mono, last, 7.0, true), 0.9 * n_same);
}

TEST_F(MatcherProjectionTest, MotionModelRotationCheckRejectsInconsistentAngles) {
  std::vector<int> pok_last;
  std::vector<int> pok;
  const Frame last =
      LastFrameWithPoints(NoisyFrame(2, &pok_last, 0.0), pok_last, map_.point_of_scene_index);
  const Frame base = NoisyFrame(3, &pok, 0.0);
  // 15% of the keypoints get a random orientation at least 24 degrees off the true one.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> off(24.f, 336.f);
  std::vector<std::uint8_t> rotated(static_cast<std::size_t>(base.size()), 0);
  Frame current = EditFrame(base, [&](FrameFeatures* f) {
    for (std::size_t i = 0; i < f->keypoints.size(); ++i) {
      if (i % 7 != 0) continue;
      f->keypoints[i].angle = std::fmod(f->keypoints[i].angle + off(rng), 360.f);
      rotated[i] = 1;
    }
  });
  current.SetPose(base.camera_from_world());
  Frame unchecked = current;
  const int n = OrbMatcher(0.9, true).SearchByProjection(&current, last, 7.0, false);
  const int n_unchecked = OrbMatcher(0.9, false).SearchByProjection(&unchecked, last, 7.0, false);
  int rotated_matched = 0;
  int rotated_matched_unchecked = 0;
  for (int i = 0; i < current.size(); ++i) {
    if (!rotated[i]) continue;
    rotated_matched += current.map_points[i] != nullptr;
    rotated_matched_unchecked += unchecked.map_points[i] != nullptr;
  }
  EXPECT_GT(rotated_matched_unchecked, 50);
  EXPECT_EQ(rotated_matched, 0);
  EXPECT_EQ(n, n_unchecked - rotated_matched_unchecked);
}

TEST_F(MatcherProjectionTest, RelocalisationSearchSkipsFoundPointsAndRespectsDistance) {
  std::vector<int> pok;
  Frame frame = NoisyFrame(3, &pok);
  frame.SetPose(
      SE3d(SO3d::Exp(Eigen::Vector3d(0.003, -0.002, 0.001)), Eigen::Vector3d(0.01, 0.01, -0.02)) *
      poses_[3]);
  const KeyFrame& kf = *map_.keyframes[2];
  // Half of the keyframe's points are already found.
  std::vector<MapPoint*> found;
  std::set<const MapPoint*> found_set;
  for (std::size_t i = 0; i < kf.map_points().size(); i += 2) {
    if (kf.map_points()[i]) {
      found.push_back(kf.map_points()[i].get());
      found_set.insert(found.back());
    }
  }
  const OrbMatcher matcher(0.9);
  const int n = matcher.SearchByProjection(&frame, kf, found, 10.0, 100);
  const Score s = ScoreFrame(frame, pok, map_.point_of_scene_index);
  EXPECT_EQ(n, s.correct + s.wrong);
  EXPECT_GT(n, 200);
  EXPECT_LT(s.wrong, 0.02 * n);
  for (const auto& mp : frame.map_points) {
    if (mp) {
      EXPECT_EQ(found_set.count(mp.get()), 0u);
    }
  }
  // A descriptor threshold below the 12 flipped bits finds far fewer.
  Frame strict = NoisyFrame(3, &pok);
  strict.SetPose(frame.camera_from_world());
  EXPECT_LT(matcher.SearchByProjection(&strict, kf, found, 10.0, 8), n / 4);
}

}  // namespace
}  // namespace pkslam
