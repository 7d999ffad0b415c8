#include "estimators/optim/ceres_setup.h"

#include <ceres/ordered_groups.h>
#include <gtest/gtest.h>

#include <atomic>

namespace pkslam {
namespace {

TEST(CeresSetup, SchurOptionsEliminateThePointsFirst) {
  double points[2][3] = {};
  double poses[3][7] = {};
  double offset = 0;
  SchurBlocks blocks;
  for (auto& p : points) blocks.AddPoint(p);
  for (auto& p : poses) blocks.AddOther(p);
  blocks.AddOther(&offset);
  blocks.free_poses = 2;
  const ceres::Solver::Options o = SchurSolverOptions(blocks, 3);
  ASSERT_NE(o.linear_solver_ordering, nullptr);
  const auto& ordering = *o.linear_solver_ordering;
  EXPECT_EQ(ordering.NumGroups(), 2);
  EXPECT_EQ(ordering.NumElements(), 6);
  for (auto& p : points) EXPECT_EQ(ordering.GroupId(p), 0);
  for (auto& p : poses) EXPECT_EQ(ordering.GroupId(p), 1);
  EXPECT_EQ(ordering.GroupId(&offset), 1);
  EXPECT_EQ(o.linear_solver_type, ceres::DENSE_SCHUR);
  EXPECT_EQ(o.num_threads, 3);
  EXPECT_EQ(o.logging_type, ceres::SILENT);
}

TEST(CeresSetup, ManyFreePosesOrAnOverrideChooseTheSolver) {
  SchurBlocks blocks;
  blocks.free_poses = kMaxFreePosesForDenseSchur + 1;
  EXPECT_EQ(SchurSolverOptions(blocks, 1).linear_solver_type, ceres::SPARSE_SCHUR);
  EXPECT_EQ(SchurSolverOptions(blocks, 1, ceres::ITERATIVE_SCHUR).linear_solver_type,
            ceres::ITERATIVE_SCHUR);
  blocks.free_poses = kMaxFreePosesForDenseSchur;
  EXPECT_EQ(SchurSolverOptions(blocks, 1).linear_solver_type, ceres::DENSE_SCHUR);
}

TEST(CeresSetup, TheAbortFlagStopsASolveSuccessfully) {
  std::atomic<bool> abort{false};
  AbortCallback callback(&abort, nullptr, nullptr, /*min_iterations=*/2);
  ceres::IterationSummary summary;
  summary.iteration = 0;
  EXPECT_EQ(callback(summary), ceres::SOLVER_CONTINUE);
  abort = true;
  summary.iteration = 1;
  EXPECT_EQ(callback(summary), ceres::SOLVER_CONTINUE);  // before min_iterations
  EXPECT_FALSE(callback.fired());
  summary.iteration = 2;
  EXPECT_EQ(callback(summary), ceres::SOLVER_TERMINATE_SUCCESSFULLY);
  EXPECT_TRUE(callback.fired());
  EXPECT_FALSE(AbortCallback(nullptr, nullptr, nullptr).active());
}

}  // namespace
}  // namespace pkslam
