#include "core/util/work_meter.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

namespace pkslam {
namespace {

TEST(WorkMeter, CountsByKindAndPricesLinearly) {
  WorkMeter meter;
  meter.Add(WorkKind::kKeyFrame, 1);
  meter.Add(WorkKind::kSolverResidual, 1000);
  meter.Add(WorkKind::kSolverResidual, 500);
  const WorkCounts before = meter.Snapshot();
  EXPECT_EQ(before, (WorkCounts{1, 0, 0, 1500}));
  meter.Add(WorkKind::kFuseProjection, 20);
  EXPECT_EQ(meter.Snapshot() - before, (WorkCounts{0, 0, 20, 0}));
  const WorkModel model{{1e-3, 2e-6, 3e-7, 4e-7}};
  EXPECT_DOUBLE_EQ(model.Seconds(before), 1e-3 + 1500 * 4e-7);
  EXPECT_DOUBLE_EQ(model.Seconds(WorkCounts{}), 0.0);
}

// Added to from several threads (a solver's callbacks and the mapping thread), nothing is lost.
TEST(WorkMeter, ConcurrentAddsAllCount) {
  WorkMeter meter;
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&meter] {
      for (int i = 0; i < 10000; ++i) meter.Add(WorkKind::kTriangulationPair, 3);
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(meter.Snapshot()[1], 4 * 10000 * 3);
}

}  // namespace
}  // namespace pkslam
