// Fusion (local mapping and loop flavours) and the Sim3-guided searches of loop closing. The
// loop tests pair a map with a second map of the same Atlas, of the same place built in a copy
// of the world scaled by 2.5 and shifted, so that the Sim3 between them is known.
#include <gtest/gtest.h>

#include <mutex>
#include <set>
#include <shared_mutex>

#include "map_model/map_editor.h"
#include "map_model/matching/matching_test_utils.h"
#include "map_model/matching/orb_matcher.h"

namespace pkslam {
namespace {

using testing::CameraFromCopiedWorld;
using testing::FrameOptions;
using testing::MakeForwardPath;
using testing::MakeMap;
using testing::MakeScene;
using testing::MakeStereoRig;
using testing::SceneIndexOf;
using testing::TransformPoses;
using testing::TransformScene;

// Map B's world: p_b = kScaleB * p + kOffsetB.
constexpr double kScaleB = 2.5;
const Eigen::Vector3d kOffsetB(12.0, -3.0, 5.0);

class MatcherFuseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = MakeStereoRig();
    scene_ = MakeScene(1200, 61);
    poses_ = MakeForwardPath(4, 0.2, 62);
    FrameOptions o;
    o.pixel_noise = 0.5;
    o.descriptor_bit_flips = 6;
    map_ = MakeMap(&atlas_, scene_, rig_, poses_, o);
    map_a_ = atlas_.current_map();
    {
      auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
      map_b_ptr_ = atlas_.CreateNewMap(lock);
    }
    o.seed = 99;
    map_b_ = MakeMap(&atlas_, TransformScene(scene_, kScaleB, kOffsetB), rig_,
                     TransformPoses(poses_, kScaleB, kOffsetB), o);
    {
      auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
      atlas_.SetCurrentMap(lock, map_a_);
    }
    scene_of_b_ = SceneIndexOf(map_b_);
    for (const auto& [id, p] : map_b_ptr_->map_points()) points_b_.push_back(p);
  }
  // Scene index of keypoint i of keyframe k of map A.
  int SceneOf(int k, int i) const { return map_.keypoint_points[k][i]; }
  // camera_from_world of keyframe k of map A, applied to map B's (scaled) world.
  Sim3d CameraFromWorldB(int k) const {
    return CameraFromCopiedWorld(poses_[k], kScaleB, kOffsetB);
  }

  Atlas atlas_;
  Map* map_a_ = nullptr;
  Map* map_b_ptr_ = nullptr;
  std::vector<MapPointPtr> points_b_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticScene scene_;
  std::vector<SE3d> poses_;
  testing::SyntheticMap map_;
  testing::SyntheticMap map_b_;
  std::map<const MapPoint*, int> scene_of_b_;
};

TEST_F(MatcherFuseTest, FuseMergesDuplicatesKeepingTheBetterObservedPoint) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  Map* map = atlas_.current_map();
  KeyFrame* kf0 = map_.keyframes[0].get();
  KeyFrame* kf3 = map_.keyframes[3].get();
  // Replace kf3's observation of 60 points seen by all keyframes with a fresh duplicate.
  std::vector<MapPointPtr> originals;
  std::vector<MapPointPtr> duplicates;
  for (const auto& p : map_.point_of_scene_index) {
    if (!p || p->observations().size() < 4 || originals.size() == 60) continue;
    const int i3 = p->IndexInKeyFrame(kf3);
    ASSERT_FALSE(p->EraseObservation(lock, kf3));
    kf3->EraseMapPointMatch(lock, i3);
    auto d = std::make_shared<MapPoint>(
        atlas_.NextMapPointId(), p->position() + Eigen::Vector3d(0.005, -0.003, 0.004), kf3, map);
    map->AddMapPoint(lock, d);
    d->AddObservation(lock, kf3, i3);
    kf3->AddMapPoint(lock, d, i3);
    d->ComputeDistinctiveDescriptor(lock);
    d->UpdateNormalAndDepth(lock);
    originals.push_back(p);
    duplicates.push_back(d);
  }
  ASSERT_EQ(originals.size(), 60u);
  // First half: duplicates projected into kf0, where the original (more observations) sits.
  // Second half: originals projected into kf3, where the duplicate (fewer) sits.
  std::vector<MapPointPtr> into_kf0(duplicates.begin(), duplicates.begin() + 30);
  std::vector<MapPointPtr> into_kf3(originals.begin() + 30, originals.end());
  const OrbMatcher matcher;
  EXPECT_EQ(matcher.Fuse(lock, kf0, into_kf0), 30);
  EXPECT_EQ(matcher.Fuse(lock, kf3, into_kf3), 30);
  for (std::size_t k = 0; k < originals.size(); ++k) {
    const MapPointPtr& p = originals[k];
    const MapPointPtr& d = duplicates[k];
    EXPECT_FALSE(p->IsBad()) << k;
    EXPECT_TRUE(d->IsBad()) << k;
    EXPECT_EQ(d->replaced_by(), p) << k;
    EXPECT_EQ(map->map_points().count(d->id()), 0u);
    const int i3 = p->IndexInKeyFrame(kf3);
    ASSERT_GE(i3, 0) << k;
    EXPECT_EQ(kf3->map_point(i3), p);
    EXPECT_EQ(p->observations().size(), map_.keyframes.size());
  }
}

TEST_F(MatcherFuseTest, FuseAddsMissingObservationsWithinTheReprojectionGate) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFrame* kf0 = map_.keyframes[0].get();
  std::vector<MapPointPtr> dropped;
  std::vector<int> slots;
  for (const auto& p : map_.point_of_scene_index) {
    if (!p || p->observations().size() < 3 || !p->IsInKeyFrame(kf0) || dropped.size() == 40) {
      continue;
    }
    const int i0 = p->IndexInKeyFrame(kf0);
    ASSERT_FALSE(p->EraseObservation(lock, kf0));
    kf0->EraseMapPointMatch(lock, i0);
    dropped.push_back(p);
    slots.push_back(i0);
  }
  ASSERT_EQ(dropped.size(), 40u);
  const OrbMatcher matcher;
  // Moved sideways by 4 sigma of the keypoint's level: outside the chi-square gate.
  const Eigen::Matrix3d world_from_camera_rotation =
      kf0->camera_from_world().RotationMatrix().transpose();
  std::vector<Eigen::Vector3d> positions;
  for (std::size_t k = 0; k < dropped.size(); ++k) {
    const auto& p = dropped[k];
    positions.push_back(p->position());
    const double z = (kf0->camera_from_world() * p->position()).z();
    const double pixels = 4.0 * rig_->pyramid.scale[kf0->keypoints_undistorted()[slots[k]].octave];
    p->SetPosition(lock, p->position() + world_from_camera_rotation *
                                             Eigen::Vector3d(pixels * z / rig_->fx, 0, 0));
  }
  EXPECT_EQ(matcher.Fuse(lock, kf0, dropped), 0);
  for (std::size_t k = 0; k < dropped.size(); ++k) dropped[k]->SetPosition(lock, positions[k]);
  EXPECT_EQ(matcher.Fuse(lock, kf0, dropped), 40);
  for (std::size_t k = 0; k < dropped.size(); ++k) {
    EXPECT_EQ(dropped[k]->IndexInKeyFrame(kf0), slots[k]);
    EXPECT_EQ(kf0->map_point(slots[k]), dropped[k]);
  }
  // Already observed: nothing to do.
  EXPECT_EQ(matcher.Fuse(lock, kf0, dropped), 0);
}

TEST_F(MatcherFuseTest, FuseIgnoresPointsWhoseDescriptorDiffers) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  Map* map = atlas_.current_map();
  KeyFrame* kf0 = map_.keyframes[0].get();
  KeyFrame* kf3 = map_.keyframes[3].get();
  // Points at the positions of kf0's observed points, with the descriptor of another keypoint.
  std::vector<MapPointPtr> impostors;
  for (int i = 0; i < kf3->size() && impostors.size() < 40; i += 3) {
    const MapPointPtr& host = kf3->map_point(i);
    if (!host || !host->IsInKeyFrame(kf0)) continue;
    const int other = (i + 1) % kf3->size();
    auto q = std::make_shared<MapPoint>(atlas_.NextMapPointId(), host->position(), kf3, map);
    q->AddObservation(lock, kf3, other);
    q->ComputeDistinctiveDescriptor(lock);
    q->UpdateNormalAndDepth(lock);
    impostors.push_back(q);
  }
  ASSERT_EQ(impostors.size(), 40u);
  EXPECT_EQ(OrbMatcher().Fuse(lock, kf0, impostors), 0);
  for (const auto& q : impostors) EXPECT_FALSE(q->IsInKeyFrame(kf0));
}

TEST_F(MatcherFuseTest, LoopSearchByProjectionWithSim3) {
  auto lock = MapReader(atlas_).Lock();
  const KeyFrame& kf = *map_.keyframes[1];
  const std::vector<MapPointPtr>& points_b = points_b_;
  // Two slots preset: kept, and their points are not matched again.
  std::vector<MapPointPtr> matched(static_cast<std::size_t>(kf.size()), nullptr);
  matched[0] = points_b[0];
  matched[1] = points_b[1];
  const int n =
      OrbMatcher(0.75).SearchByProjection(kf, CameraFromWorldB(1), points_b, &matched, 10.0, 1.0);
  EXPECT_EQ(matched[0], points_b[0]);
  EXPECT_EQ(matched[1], points_b[1]);
  int correct = 0;
  int wrong = 0;
  int findable = 0;
  for (int i = 2; i < kf.size(); ++i) {
    findable += map_b_.point_of_scene_index[SceneOf(1, i)] != nullptr;
    if (!matched[i]) continue;
    EXPECT_NE(matched[i], points_b[0]);
    EXPECT_NE(matched[i], points_b[1]);
    (scene_of_b_.at(matched[i].get()) == SceneOf(1, i) ? correct : wrong)++;
  }
  EXPECT_EQ(n, correct + wrong);
  RecordProperty("correct", correct);
  RecordProperty("wrong", wrong);
  RecordProperty("findable", findable);
  EXPECT_GT(correct, 0.85 * findable) << findable;
  EXPECT_LE(wrong, 0.01 * n);
  // A wrong scale (1.2x) moves the projections: few matches.
  const Sim3d s_true = CameraFromWorldB(1);
  const Sim3d wrong_scale(1.2 * s_true.scale(), s_true.so3(), s_true.translation());
  std::vector<MapPointPtr> none;
  EXPECT_LT(OrbMatcher(0.75).SearchByProjection(kf, wrong_scale, points_b, &none, 10.0, 1.0),
            n / 10);
}

TEST_F(MatcherFuseTest, LoopFuseWithSim3ReportsReplacementsAndFillsEmptySlots) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFrame* kf = map_.keyframes[1].get();
  // Empty 30 of kf's slots (their points keep other observations).
  std::set<int> emptied;
  for (int i = 0; i < kf->size() && emptied.size() < 30; i += 5) {
    const MapPointPtr p = kf->map_point(i);
    if (!p || p->observations().size() < 3) continue;
    ASSERT_FALSE(p->EraseObservation(lock, kf));
    kf->EraseMapPointMatch(lock, i);
    emptied.insert(i);
  }
  const std::vector<MapPointPtr>& points_b = points_b_;
  std::vector<MapPointPtr> replace_with;
  const int n = OrbMatcher().Fuse(lock, kf, CameraFromWorldB(1), points_b, 4.0, &replace_with);
  ASSERT_EQ(replace_with.size(), points_b.size());
  int replaced_correct = 0;
  int replaced_wrong = 0;
  for (std::size_t j = 0; j < points_b.size(); ++j) {
    if (!replace_with[j]) continue;
    const int scene_index = scene_of_b_.at(points_b[j].get());
    (replace_with[j] == map_.point_of_scene_index[scene_index] ? replaced_correct
                                                               : replaced_wrong)++;
  }
  // Slots now holding a point of map B: the emptied ones and those that never had a point.
  int filled = 0;
  int filled_wrong = 0;
  int emptied_filled = 0;
  for (int i = 0; i < kf->size(); ++i) {
    const MapPointPtr& p = kf->map_point(i);
    if (!p || !scene_of_b_.count(p.get())) continue;
    EXPECT_EQ(p->IndexInKeyFrame(kf), i);
    ++filled;
    filled_wrong += scene_of_b_.at(p.get()) != SceneOf(1, i);
    emptied_filled += emptied.count(i) > 0;
  }
  EXPECT_GT(replaced_correct, 300);
  EXPECT_LE(replaced_wrong, 0.01 * replaced_correct);
  EXPECT_GE(emptied_filled, 27);
  EXPECT_EQ(filled_wrong, 0);
  EXPECT_EQ(n, replaced_correct + replaced_wrong + filled);
}

TEST_F(MatcherFuseTest, SearchBySim3FindsMutualMatches) {
  auto lock = MapReader(atlas_).Lock();
  const KeyFrame& kf1 = *map_.keyframes[1];
  const KeyFrame& kf2 = *map_b_.keyframes[2];
  // p_cam1 = S12 * p_cam2, with map B's camera coordinates scaled by kScaleB.
  const SE3d cam1_from_cam2 = poses_[1] * poses_[2].Inverse();
  const Sim3d s12(1.0 / kScaleB, cam1_from_cam2.so3(), cam1_from_cam2.translation());
  std::vector<MapPointPtr> matches12(static_cast<std::size_t>(kf1.size()), nullptr);
  // A known pair stays and is not searched again.
  int preset = -1;
  for (int i1 = 0; i1 < kf1.size() && preset < 0; ++i1) {
    const MapPointPtr& b = map_b_.point_of_scene_index[SceneOf(1, i1)];
    if (kf1.map_point(i1) && b && b->IsInKeyFrame(&kf2)) preset = i1;
  }
  ASSERT_GE(preset, 0);
  const MapPointPtr preset_point = map_b_.point_of_scene_index[SceneOf(1, preset)];
  matches12[preset] = preset_point;
  const OrbMatcher matcher;
  const int n = matcher.SearchBySim3(kf1, kf2, &matches12, s12, 7.5);
  EXPECT_EQ(matches12[preset], preset_point);
  int correct = 0;
  int wrong = 0;
  int findable = 0;
  for (int i1 = 0; i1 < kf1.size(); ++i1) {
    if (i1 == preset) continue;
    const MapPointPtr& b = map_b_.point_of_scene_index[SceneOf(1, i1)];
    findable += kf1.map_point(i1) && b && b->IsInKeyFrame(&kf2);
    if (!matches12[i1]) continue;
    EXPECT_NE(matches12[i1], preset_point);
    (matches12[i1] == b ? correct : wrong)++;
  }
  EXPECT_EQ(n, correct + wrong);
  RecordProperty("correct", correct);
  RecordProperty("wrong", wrong);
  RecordProperty("findable", findable);
  EXPECT_GT(correct, 0.85 * findable) << findable;
  EXPECT_LE(wrong, 0.01 * n);
  // A Sim3 rotated by 3 degrees projects everything tens of pixels away.
  const Sim3d off(s12.scale(), SO3d::Exp(Eigen::Vector3d(0, 0.05, 0)) * s12.so3(),
                  s12.translation());
  std::vector<MapPointPtr> off_matches;
  EXPECT_LT(matcher.SearchBySim3(kf1, kf2, &off_matches, off, 7.5), n / 10);
}

}  // namespace
}  // namespace pkslam
