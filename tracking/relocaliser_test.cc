// Relocalisation (tracking/relocaliser.h) of synthetic frames against a synthetic stereo map
// with BoW and a keyframe database.
#include "tracking/relocaliser.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "map_model/keyframe.h"
#include "map_model/keyframe_database.h"
#include "map_model/map_editor.h"
#include "map_model/matching/matching_test_utils.h"

namespace pkslam {
namespace {

class RelocaliserTest : public ::testing::Test {
 protected:
  void SetUp() override {
    database_ = std::make_unique<KeyFrameDatabase>(bow_.vocabulary);
    auto lock = MapEditor(&bow_.atlas).Write(MapEdit::kFixture);
    for (const KeyFramePtr& kf : bow_.map.keyframes) database_->Add(lock, kf.get());
  }
  // A frame of `scene` near keyframe 2's pose (5 cm and 1 degree off), without a pose.
  Frame Query(const testing::SyntheticScene& scene) const {
    testing::FrameOptions options;
    options.pixel_noise = 0.5;
    options.seed = 77;
    std::vector<int> unused;
    return testing::MakeFrame(scene, bow_.rig, TruePose(), 100, 5'000'000'000, options, &unused);
  }
  SE3d TruePose() const {
    return SE3d(SO3d::Exp(Eigen::Vector3d(0, 0.017, 0)), Eigen::Vector3d(0.05, 0, 0)) *
           bow_.poses[2];
  }

  std::unique_ptr<KeyFrameDatabase> database_;
  RelocalisationOptions options_;
  testing::StereoBowMap bow_{800, 21, 5, 9};
};

TEST_F(RelocaliserTest, AFrameOfTheMappedPlaceFindsItsPose) {
  Frame frame = Query(bow_.scene);
  auto lock = MapReader(bow_.atlas).Lock();
  const RelocalisationResult result = RelocaliseFrame(*database_, bow_.atlas.current_map(),
                                                      bow_.vocabulary, *bow_.rig, options_, &frame);
  ASSERT_TRUE(result.success);
  EXPECT_GE(result.inliers, kMinRelocalisationInliers);
  EXPECT_GT(result.places, 0u);
  EXPECT_GT(result.candidates, 0u);
  const SE3d error = frame.camera_from_world() * TruePose().Inverse();
  EXPECT_LT(error.translation().norm(), 0.02);
  EXPECT_LT(error.so3().Log().norm(), 0.005);
  int matched = 0;
  for (int i = 0; i < frame.size(); ++i) {
    matched += frame.map_points[i] ? 1 : 0;
    EXPECT_EQ(frame.outliers[i], 0) << "outliers are removed";
  }
  EXPECT_EQ(matched, result.inliers);
}

TEST_F(RelocaliserTest, TheSameSeedGivesTheSamePoseAndTheWideSearchFindsItToo) {
  Frame a = Query(bow_.scene);
  Frame b = Query(bow_.scene);
  Frame wide = Query(bow_.scene);
  auto lock = MapReader(bow_.atlas).Lock();
  ASSERT_TRUE(RelocaliseFrame(*database_, bow_.atlas.current_map(), bow_.vocabulary, *bow_.rig,
                              options_, &a)
                  .success);
  ASSERT_TRUE(RelocaliseFrame(*database_, bow_.atlas.current_map(), bow_.vocabulary, *bow_.rig,
                              options_, &b)
                  .success);
  EXPECT_EQ(a.camera_from_world().translation(), b.camera_from_world().translation());
  RelocalisationOptions wide_options = options_;
  wide_options.wide = true;
  wide_options.wide_candidates = 2;
  const RelocalisationResult result = RelocaliseFrame(
      *database_, bow_.atlas.current_map(), bow_.vocabulary, *bow_.rig, wide_options, &wide);
  EXPECT_TRUE(result.success);
  EXPECT_LE(result.places, 2u) << "at most wide_candidates places";
}

TEST_F(RelocaliserTest, AFrameOfAnotherPlaceIsNotRelocalised) {
  Frame frame = Query(testing::MakeScene(800, 1234));  // other points, other descriptors
  auto lock = MapReader(bow_.atlas).Lock();
  const RelocalisationResult result = RelocaliseFrame(*database_, bow_.atlas.current_map(),
                                                      bow_.vocabulary, *bow_.rig, options_, &frame);
  EXPECT_FALSE(result.success);
  for (const MapPointPtr& mp : frame.map_points) EXPECT_EQ(mp, nullptr);
}

TEST_F(RelocaliserTest, FailuresInARowWidenTheSearchUntilOneSucceeds) {
  RelocalisationAttempts attempts(/*widen_after=*/2, /*wide_candidates=*/3, options_.pose);
  const testing::SyntheticScene elsewhere = testing::MakeScene(800, 1234);
  auto lock = MapReader(bow_.atlas).Lock();
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(attempts.NextIsWide(), k >= 2) << "attempt " << k;
    Frame lost = Query(elsewhere);
    EXPECT_FALSE(
        attempts.Try(*database_, bow_.atlas.current_map(), bow_.vocabulary, *bow_.rig, 5, &lost)
            .success);
    EXPECT_EQ(attempts.failures_in_a_row(), k + 1);
  }
  EXPECT_EQ(attempts.successes(), 0);
  Frame found = Query(bow_.scene);
  const RelocalisationResult wide =
      attempts.Try(*database_, bow_.atlas.current_map(), bow_.vocabulary, *bow_.rig, 5, &found);
  ASSERT_TRUE(wide.success);
  EXPECT_LE(wide.places, 3u) << "the wide search's candidate cap";
  EXPECT_EQ(attempts.successes(), 1);
  EXPECT_EQ(attempts.failures_in_a_row(), 0);
  EXPECT_FALSE(attempts.NextIsWide()) << "a success narrows the search again";
}

}  // namespace
}  // namespace pkslam
