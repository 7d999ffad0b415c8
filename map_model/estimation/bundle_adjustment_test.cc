#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <random>
#include <set>
#include <shared_mutex>
#include <string>
#include <unordered_map>

#include "core/util/error.h"
#include "estimators/optim/bundle_adjustment_internal.h"
#include "estimators/optim/reprojection_error.h"
#include "map_model/estimation/bundle_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

using testing::FrameOptions;
using testing::MakeForwardPath;
using testing::MakeMap;
using testing::MakeScene;
using testing::MakeStereoRig;

constexpr double kDeg = M_PI / 180.0;

class BundleAdjustmentTest : public ::testing::Test {
 protected:
  void Build(bool stereo, double noise = 0.0, double outliers = 0.0, int num_keyframes = 10) {
    rig_ = MakeStereoRig(stereo ? Sensor::kStereo : Sensor::kMonocular);
    scene_ = MakeScene(800, 21);
    poses_ = MakeForwardPath(num_keyframes, 0.2, 22);
    FrameOptions o;
    o.stereo = stereo;
    o.pixel_noise = noise;
    o.outlier_fraction = outliers;
    o.seed = 23;
    map_ = MakeMap(&atlas_, scene_, rig_, poses_, o);
    for (std::size_t i = 0; i < map_.point_of_scene_index.size(); ++i) {
      if (map_.point_of_scene_index[i]) scene_index_[map_.point_of_scene_index[i].get()] = i;
    }
    for (std::size_t k = 0; k < map_.keyframes.size(); ++k) kf_index_[map_.keyframes[k].get()] = k;
  }

  KeyFrame* LastKeyFrame() const { return map_.keyframes.back().get(); }
  // The map objects a problem names by id.
  // The map objects a problem names by id (null: no longer in the map).
  KeyFrame* KeyFrameOf(const BundleProblem::KeyFrameState& k) const {
    return atlas_.current_map()->KeyFrameById(k.keyframe_id).get();
  }
  MapPointPtr PointOf(const BundleProblem::PointState& p) const {
    return atlas_.current_map()->MapPointById(p.point_id);
  }
  const SE3d& TruePose(const BundleProblem::KeyFrameState& k) const {
    return poses_[kf_index_.at(KeyFrameOf(k))];
  }
  const Eigen::Vector3d& TruePoint(const BundleProblem::PointState& p) const {
    return scene_.points_world[scene_index_.at(PointOf(p).get())];
  }

  // Moves free keyframes by up to 2 cm / 0.5 degrees per axis and every point by up to 3 cm
  // per axis (times scale).
  void Perturb(BundleProblem* problem, std::uint64_t seed, double scale = 1.0) const {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-scale, scale);
    for (auto& k : problem->keyframes) {
      if (k.fixed) continue;
      Eigen::Matrix<double, 6, 1> d;
      d << 0.02 * u(rng), 0.02 * u(rng), 0.02 * u(rng), 0.5 * kDeg * u(rng), 0.5 * kDeg * u(rng),
          0.5 * kDeg * u(rng);
      k.camera_from_world = SE3d::Exp(d) * k.camera_from_world;
    }
    for (auto& p : problem->points)
      p.position_world += 0.03 * Eigen::Vector3d(u(rng), u(rng), u(rng));
  }

  static BundleResult InputAsResult(const BundleProblem& problem) {
    BundleResult r;
    for (const auto& k : problem.keyframes) r.camera_from_world.push_back(k.camera_from_world);
    for (const auto& p : problem.points) r.points_world.push_back(p.position_world);
    return r;
  }

  struct Errors {
    double max_translation = 0, max_rotation_deg = 0, max_point = 0;
  };
  Errors ErrorsOf(const BundleProblem& problem, const BundleResult& r) const {
    Errors e;
    for (std::size_t i = 0; i < problem.keyframes.size(); ++i) {
      const SE3d& truth = TruePose(problem.keyframes[i]);
      const SE3d diff = r.camera_from_world[i] * truth.Inverse();
      e.max_translation = std::max(
          e.max_translation,
          (r.camera_from_world[i].Inverse().translation() - truth.Inverse().translation()).norm());
      e.max_rotation_deg = std::max(e.max_rotation_deg, diff.so3().Angle() / kDeg);
    }
    for (std::size_t i = 0; i < problem.points.size(); ++i) {
      e.max_point =
          std::max(e.max_point, (r.points_world[i] - TruePoint(problem.points[i])).norm());
    }
    return e;
  }

  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticScene scene_;
  std::vector<SE3d> poses_;
  testing::SyntheticMap map_;
  std::unordered_map<const MapPoint*, std::size_t> scene_index_;
  std::unordered_map<const KeyFrame*, std::size_t> kf_index_;
};

TEST_F(BundleAdjustmentTest, LocalBundleHasOrbSlamStructure) {
  Build(true);
  BundleAdjustmentOptions options;
  options.max_local_keyframes = 4;
  auto lock = MapReader(atlas_).Lock();
  KeyFrame* kf = LastKeyFrame();
  const BundleProblem problem = CollectLocalBundle(lock, kf, options);
  ASSERT_FALSE(problem.empty());
  EXPECT_EQ(problem.fx, rig_->fx);
  EXPECT_EQ(problem.bf, rig_->bf);

  // Local: the keyframe then its three best covisibles, in weight order, all free.
  std::set<const KeyFrame*> local;
  ASSERT_GE(kf->CovisiblesByWeight().size(), 3u);
  EXPECT_EQ(KeyFrameOf(problem.keyframes[0]), kf);
  for (int i = 0; i < 4; ++i) {
    if (i > 0) {
      EXPECT_EQ(KeyFrameOf(problem.keyframes[i]), kf->CovisiblesByWeight()[i - 1]);
    }
    EXPECT_FALSE(problem.keyframes[i].fixed);
    local.insert(KeyFrameOf(problem.keyframes[i]));
  }
  // Points: exactly the good points of the local keyframes.
  std::set<const MapPoint*> expected_points;
  for (const KeyFrame* k : local) {
    for (const auto& p : k->GoodMapPoints()) expected_points.insert(p.get());
  }
  std::set<const MapPoint*> points;
  for (const auto& p : problem.points) points.insert(PointOf(p).get());
  EXPECT_EQ(points, expected_points);
  // Fixed: exactly the other observers of those points, including the origin.
  std::set<const KeyFrame*> expected_fixed;
  for (const MapPoint* p : expected_points) {
    for (const auto& [id, obs] : p->observations()) {
      if (local.count(obs.keyframe) == 0) expected_fixed.insert(obs.keyframe);
    }
  }
  std::set<const KeyFrame*> fixed;
  for (std::size_t i = 4; i < problem.keyframes.size(); ++i) {
    EXPECT_TRUE(problem.keyframes[i].fixed);
    fixed.insert(KeyFrameOf(problem.keyframes[i]));
  }
  EXPECT_EQ(fixed, expected_fixed);
  EXPECT_TRUE(fixed.count(map_.keyframes[0].get()));
  // Observations: one per (point, problem keyframe) pair, consistent with the map.
  std::size_t expected_obs = 0;
  for (const MapPoint* p : expected_points) expected_obs += p->observations().size();
  EXPECT_EQ(problem.observations.size(), expected_obs);
  for (const auto& o : problem.observations) {
    const KeyFrame* k = KeyFrameOf(problem.keyframes[o.keyframe_index]);
    const MapPoint* p = PointOf(problem.points[o.point_index]).get();
    EXPECT_EQ(p->IndexInKeyFrame(k), o.keypoint_index);
    EXPECT_GE(o.u_right, 0.0);  // stereo rig: every synthetic keypoint has a right match
    EXPECT_DOUBLE_EQ(o.inv_sigma2,
                     rig_->pyramid.inv_sigma2[k->keypoints_undistorted()[o.keypoint_index].octave]);
  }
}

TEST_F(BundleAdjustmentTest, OriginIsFixedEvenWhenLocal) {
  Build(true);
  auto lock = MapReader(atlas_).Lock();
  const BundleProblem problem = CollectLocalBundle(lock, map_.keyframes[0].get(), {});
  ASSERT_FALSE(problem.empty());
  EXPECT_EQ(KeyFrameOf(problem.keyframes[0]), map_.keyframes[0].get());
  EXPECT_TRUE(problem.keyframes[0].fixed);
  int free_keyframes = 0;
  for (const auto& k : problem.keyframes) free_keyframes += k.fixed ? 0 : 1;
  EXPECT_GT(free_keyframes, 0);
}

TEST_F(BundleAdjustmentTest, StereoLocalBundleReturnsToTruth) {
  Build(true);
  BundleProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    problem = CollectLocalBundle(lock, LastKeyFrame(), {});
  }
  Perturb(&problem, 5);
  const Errors before = ErrorsOf(problem, InputAsResult(problem));
  EXPECT_GT(before.max_point, 0.02);
  const BundleResult r = SolveBundle(problem, {});
  EXPECT_FALSE(r.aborted);
  EXPECT_TRUE(r.outlier_observations.empty());
  EXPECT_LT(r.final_cost, 1e-6 * r.initial_cost);
  const Errors e = ErrorsOf(problem, r);
  EXPECT_LT(e.max_translation, 1e-4);
  EXPECT_LT(e.max_rotation_deg, 0.005);
  EXPECT_LT(e.max_point, 1e-3);
  // The gauge keyframes come back untouched.
  for (std::size_t i = 0; i < problem.keyframes.size(); ++i) {
    if (!problem.keyframes[i].fixed) continue;
    EXPECT_EQ(r.camera_from_world[i].Matrix(), problem.keyframes[i].camera_from_world.Matrix());
  }
}

TEST_F(BundleAdjustmentTest, MonocularLocalBundleReturnsToTruth) {
  // Monocular: the gauge (including scale) is held by several fixed keyframes.
  Build(false, 0.0, 0.0, 12);
  BundleAdjustmentOptions options;
  options.max_local_keyframes = 5;
  options.iterations_second = 30;
  BundleProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    problem = CollectLocalBundle(lock, LastKeyFrame(), options);
  }
  int fixed = 0;
  for (const auto& k : problem.keyframes) fixed += k.fixed ? 1 : 0;
  ASSERT_GE(fixed, 2);
  for (const auto& o : problem.observations) ASSERT_LT(o.u_right, 0.0);
  Perturb(&problem, 6);
  const BundleResult r = SolveBundle(problem, options);
  EXPECT_TRUE(r.outlier_observations.empty());
  const Errors e = ErrorsOf(problem, r);
  EXPECT_LT(e.max_translation, 1e-3);
  EXPECT_LT(e.max_rotation_deg, 0.01);
  EXPECT_LT(e.max_point, 5e-3);
}

TEST_F(BundleAdjustmentTest, GlobalBundleFixesOnlyTheOrigin) {
  Build(true);
  BundleProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    problem = CollectGlobalBundle(lock, *atlas_.current_map());
    EXPECT_EQ(problem.keyframes.size(), map_.keyframes.size());
    EXPECT_EQ(static_cast<int>(problem.points.size()), atlas_.current_map()->NumMapPoints());
  }
  for (std::size_t i = 0; i < problem.keyframes.size(); ++i) {
    EXPECT_EQ(KeyFrameOf(problem.keyframes[i]), map_.keyframes[i].get());
    EXPECT_EQ(problem.keyframes[i].fixed, i == 0);
  }
  Perturb(&problem, 7);
  const Errors e = ErrorsOf(problem, SolveBundle(problem, {}));
  EXPECT_LT(e.max_translation, 1e-4);
  EXPECT_LT(e.max_point, 1e-3);
}

TEST_F(BundleAdjustmentTest, OutlierObservationsAreDetectedAndErased) {
  Build(true, 0.5, 0.05);
  BundleProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    problem = CollectLocalBundle(lock, LastKeyFrame(), {});
  }
  // Ground truth: observations far (> 10 px) from the true projection were moved. Points
  // with as many moved observations as good ones are ambiguous and left out of `near`.
  std::set<int> moved, near;
  std::vector<int> num_obs(problem.points.size(), 0), num_moved(problem.points.size(), 0);
  std::vector<double> error(problem.observations.size());
  for (std::size_t i = 0; i < problem.observations.size(); ++i) {
    const auto& o = problem.observations[i];
    const auto uv = rig_->camera.Project(TruePose(problem.keyframes[o.keyframe_index]) *
                                         TruePoint(problem.points[o.point_index]));
    error[i] = (*uv - o.uv).norm();
    ++num_obs[o.point_index];
    if (error[i] > 10.0) ++num_moved[o.point_index];
  }
  for (std::size_t i = 0; i < problem.observations.size(); ++i) {
    const int p = problem.observations[i].point_index;
    if (error[i] > 10.0) moved.insert(static_cast<int>(i));
    if (error[i] < 3.0 && 2 * num_moved[p] < num_obs[p]) near.insert(static_cast<int>(i));
  }
  ASSERT_GT(moved.size(), 20u);
  // Local BA refines estimates that tracking and triangulation made already good: a smaller
  // perturbation than in the convergence tests, so 5 robust iterations converge.
  Perturb(&problem, 8, 0.25);
  const BundleResult r = SolveBundle(problem, {});
  const std::set<int> flagged(r.outlier_observations.begin(), r.outlier_observations.end());
  for (int i : moved) EXPECT_TRUE(flagged.count(i)) << i;
  for (int i : near) EXPECT_FALSE(flagged.count(i)) << i;
  const Errors e = ErrorsOf(problem, r);
  EXPECT_LT(e.max_translation, 5e-3);  // 0.5 px noise, gauge held by the origin only

  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  ApplyBundle(lock, atlas_.current_map(), problem, r);
  for (int i : flagged) {
    const auto& o = problem.observations[i];
    const KeyFrame* kf = KeyFrameOf(problem.keyframes[o.keyframe_index]);
    const MapPointPtr p = PointOf(problem.points[o.point_index]);
    EXPECT_EQ(kf->map_point(o.keypoint_index), nullptr);
    if (p != nullptr) {  // (null: retired, no observations left)
      EXPECT_FALSE(p->IsInKeyFrame(kf));
    }
  }
  // Kept observations are still linked both ways.
  for (int i : near) {
    const auto& o = problem.observations[i];
    const KeyFrame* kf = KeyFrameOf(problem.keyframes[o.keyframe_index]);
    const MapPointPtr p = PointOf(problem.points[o.point_index]);
    if (p == nullptr || p->IsBad()) continue;
    EXPECT_EQ(kf->map_point(o.keypoint_index), p);
  }
}

TEST_F(BundleAdjustmentTest, ApplyWritesFreeEntitiesAndSkipsBadOnes) {
  Build(true);
  BundleProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    problem = CollectLocalBundle(lock, LastKeyFrame(), {});
  }
  Perturb(&problem, 9);
  const BundleResult r = SolveBundle(problem, {});
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  // Between Solve and Apply, local mapping culled a point and a keyframe.
  const MapPointPtr culled = PointOf(problem.points[3]);
  const Eigen::Vector3d culled_position = culled->position();
  culled->SetBad(lock);
  int retired = -1;
  for (std::size_t i = 1; i < problem.keyframes.size(); ++i) {
    if (!problem.keyframes[i].fixed) {
      retired = static_cast<int>(i);
      break;
    }
  }
  ASSERT_GT(retired, 0);
  const KeyFramePtr retired_kf =
      atlas_.current_map()->KeyFrameById(problem.keyframes[retired].keyframe_id);
  retired_kf->SetBad(lock);  // leaves the map's live keyframes
  EXPECT_EQ(KeyFrameOf(problem.keyframes[retired]), nullptr);
  const SE3d retired_pose = retired_kf->camera_from_world();
  ApplyBundle(lock, atlas_.current_map(), problem, r);
  EXPECT_EQ(culled->position(), culled_position);
  EXPECT_EQ(retired_kf->camera_from_world().Matrix(), retired_pose.Matrix());
  for (std::size_t i = 0; i < problem.keyframes.size(); ++i) {
    const auto& k = problem.keyframes[i];
    if (k.fixed || static_cast<int>(i) == retired) continue;
    EXPECT_EQ(KeyFrameOf(k)->camera_from_world().Matrix(), r.camera_from_world[i].Matrix());
  }
  for (std::size_t i = 0; i < problem.points.size(); ++i) {
    const MapPointPtr p = PointOf(problem.points[i]);
    if (p == nullptr || p->IsBad()) continue;  // retired (by the outlier erasure or culling)
    EXPECT_EQ(p->position(), r.points_world[i]);
  }
}

TEST_F(BundleAdjustmentTest, AbortBeforeStartReturnsTheInput) {
  Build(true);
  BundleProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    problem = CollectLocalBundle(lock, LastKeyFrame(), {});
  }
  Perturb(&problem, 10);
  const std::atomic<bool> abort{true};
  const BundleResult r = SolveBundle(problem, {}, &abort);
  EXPECT_TRUE(r.aborted);
  EXPECT_EQ(r.iterations, 0);
  for (std::size_t i = 0; i < problem.points.size(); ++i) {
    EXPECT_EQ(r.points_world[i], problem.points[i].position_world);
  }
}

// Sets the abort flag once the solver reaches a given iteration.
class AbortAt final : public ceres::IterationCallback {
 public:
  AbortAt(std::atomic<bool>* flag, int iteration) : flag_(flag), iteration_(iteration) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (s.iteration >= iteration_) flag_->store(true);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  std::atomic<bool>* flag_;
  int iteration_;
};

TEST_F(BundleAdjustmentTest, AbortMidwayKeepsTheProgress) {
  Build(true);
  BundleProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    problem = CollectLocalBundle(lock, LastKeyFrame(), {});
  }
  Perturb(&problem, 11);
  std::atomic<bool> abort{false};
  AbortAt trigger(&abort, 2);
  internal::BundleSolverOverrides overrides;
  overrides.callback = &trigger;
  const BundleResult r = internal::SolveBundle(problem, {}, &abort, overrides);
  EXPECT_TRUE(r.aborted);
  EXPECT_EQ(r.iterations, 2);
  const Errors before = ErrorsOf(problem, InputAsResult(problem));
  const Errors after = ErrorsOf(problem, r);
  EXPECT_LT(after.max_point, 0.5 * before.max_point);
}

// The work meter (live emulation's work clock) counts every residual evaluation as it happens:
// iterations 0 (the initial evaluation), 1 and 2 of the aborted first pass, each over all the
// problem's scalar residuals (stereo 3, monocular 2).
TEST_F(BundleAdjustmentTest, WorkMeterCountsResidualEvaluations) {
  Build(true);
  BundleProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    problem = CollectLocalBundle(lock, LastKeyFrame(), {});
  }
  Perturb(&problem, 11);
  std::int64_t residuals = 0;
  for (const auto& o : problem.observations) residuals += o.u_right >= 0 ? 3 : 2;
  std::atomic<bool> abort{false};
  AbortAt trigger(&abort, 2);
  WorkMeter work;
  internal::BundleSolverOverrides overrides;
  overrides.callback = &trigger;
  overrides.work = &work;
  const BundleResult r = internal::SolveBundle(problem, {}, &abort, overrides);
  ASSERT_TRUE(r.aborted);
  const WorkCounts counts = work.Snapshot();
  EXPECT_EQ(counts[static_cast<std::size_t>(WorkKind::kSolverResidual)], 3 * residuals);
  EXPECT_EQ(counts[static_cast<std::size_t>(WorkKind::kKeyFrame)], 0);
  // A whole solve counts more, and the same problem counts the same again.
  WorkMeter full1;
  WorkMeter full2;
  SolveBundle(problem, {}, nullptr, &full1);
  SolveBundle(problem, {}, nullptr, &full2);
  EXPECT_GT(full1.Snapshot()[3], counts[3]);
  EXPECT_EQ(full1.Snapshot(), full2.Snapshot());
}

TEST_F(BundleAdjustmentTest, SingleThreadedIsBitIdentical) {
  Build(true, 1.0, 0.03);
  BundleProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    problem = CollectLocalBundle(lock, LastKeyFrame(), {});
  }
  Perturb(&problem, 12);
  const BundleResult a = SolveBundle(problem, {});
  const BundleResult b = SolveBundle(problem, {});
  EXPECT_EQ(a.outlier_observations, b.outlier_observations);
  EXPECT_EQ(a.iterations, b.iterations);
  ASSERT_EQ(a.points_world.size(), b.points_world.size());
  for (std::size_t i = 0; i < a.points_world.size(); ++i) {
    ASSERT_EQ(std::memcmp(a.points_world[i].data(), b.points_world[i].data(), 3 * sizeof(double)),
              0);
  }
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a over the result bytes
  auto mix = [&hash](const double* data, std::size_t n) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n * sizeof(double); ++i)
      hash = (hash ^ bytes[i]) * 1099511628211ull;
  };
  for (std::size_t i = 0; i < a.camera_from_world.size(); ++i) {
    const Eigen::Matrix4d ma = a.camera_from_world[i].Matrix();
    const Eigen::Matrix4d mb = b.camera_from_world[i].Matrix();
    ASSERT_EQ(std::memcmp(ma.data(), mb.data(), sizeof(ma)), 0);
    mix(ma.data(), 16);
  }
  for (const auto& p : a.points_world) mix(p.data(), 3);
  // Across processes (heap addresses differ): compare this between two runs with
  // --gtest_output=xml.
  RecordProperty("result_fnv1a", std::to_string(hash));
}

TEST_F(BundleAdjustmentTest, DenseAndSparseSchurAgree) {
  Build(true, 1.0);
  BundleProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    problem = CollectLocalBundle(lock, LastKeyFrame(), {});
  }
  Perturb(&problem, 13);
  internal::BundleSolverOverrides dense, sparse;
  dense.linear_solver = ceres::DENSE_SCHUR;
  sparse.linear_solver = ceres::SPARSE_SCHUR;
  const BundleResult a = internal::SolveBundle(problem, {}, nullptr, sparse);
  const BundleResult b = internal::SolveBundle(problem, {}, nullptr, dense);
  EXPECT_EQ(a.outlier_observations, b.outlier_observations);
  for (std::size_t i = 0; i < a.points_world.size(); ++i) {
    EXPECT_LT((a.points_world[i] - b.points_world[i]).norm(), 1e-6);
  }
}

TEST_F(BundleAdjustmentTest, PointBehindACameraIsAnOutlierFromTheStart) {
  Build(true);
  BundleProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    problem = CollectLocalBundle(lock, LastKeyFrame(), {});
  }
  // Mirror point 0 through the first observing camera's centre.
  const auto it = std::find_if(problem.observations.begin(), problem.observations.end(),
                               [](const auto& o) { return o.point_index == 0; });
  ASSERT_NE(it, problem.observations.end());
  const SE3d& camera_from_world = problem.keyframes[it->keyframe_index].camera_from_world;
  problem.points[0].position_world =
      camera_from_world.Inverse() * (-(camera_from_world * problem.points[0].position_world));
  const BundleResult r = SolveBundle(problem, {});
  const std::set<int> flagged(r.outlier_observations.begin(), r.outlier_observations.end());
  EXPECT_TRUE(flagged.count(static_cast<int>(it - problem.observations.begin())));
}

TEST_F(BundleAdjustmentTest, EmptyProblemsAndBadOptions) {
  const BundleResult r = SolveBundle(BundleProblem{}, {});
  EXPECT_FALSE(r.aborted);
  EXPECT_TRUE(r.camera_from_world.empty());
  BundleAdjustmentOptions o;
  o.iterations_first = 0;
  EXPECT_THROW(o.Check(), OptionError);
  Map empty_map(99);
  Build(true);
  auto released = MapReader(atlas_).Lock();
  released.unlock();
  EXPECT_THROW(CollectGlobalBundle(released, *atlas_.current_map()), Error);
  EXPECT_THROW(CollectLocalBundle(released, LastKeyFrame(), {}), Error);
  const auto lock = MapReader(atlas_).Lock();
  EXPECT_TRUE(CollectGlobalBundle(lock, empty_map).empty());
}

}  // namespace
}  // namespace pkslam
