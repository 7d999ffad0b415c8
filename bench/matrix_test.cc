#include "bench/matrix.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace pkslam::bench {
namespace {

// Datasets x configurations x runs in the matrix's order (dataset, configuration, run).
std::vector<RunSpec> Matrix(const std::vector<std::string>& datasets, int configs, int runs) {
  std::vector<RunSpec> out;
  for (const auto& d : datasets) {
    for (int c = 0; c < configs; ++c) {
      for (int r = 0; r < runs; ++r) {
        RunSpec s;
        s.index = static_cast<int>(out.size());
        s.dataset = d;
        s.config = fmt::format("c{}", c);
        s.run = r;
        s.id = fmt::format("{}/{}/seed{}", d, s.config, r + 1);
        out.push_back(s);
      }
    }
  }
  return out;
}

std::vector<const RunSpec*> Pointers(const std::vector<RunSpec>& runs) {
  std::vector<const RunSpec*> out;
  for (const auto& r : runs) out.push_back(&r);
  return out;
}

std::vector<std::string> Ids(const std::vector<const RunSpec*>& runs) {
  std::vector<std::string> out;
  for (const RunSpec* r : runs) out.push_back(r->id);
  return out;
}

TEST(RenderingOrderTest, ARenderingPerRunPutsRunOneOfEveryDatasetBeforeRunTwoOfAny) {
  const auto runs = Matrix({"A", "B"}, 2, 2);
  const auto order = RenderingOrder(Pointers(runs), [](const RunSpec& r) {
    return std::optional<std::string>(fmt::format("{}{}", r.dataset, r.run));
  });
  const std::vector<std::string> expected = {"A/c0/seed1", "A/c1/seed1", "B/c0/seed1",
                                             "B/c1/seed1", "A/c0/seed2", "A/c1/seed2",
                                             "B/c0/seed2", "B/c1/seed2"};
  EXPECT_EQ(Ids(order), expected);
}

TEST(RenderingOrderTest, ARenderingSharedByAllRunsKeepsItsRunsTogether) {
  const auto runs = Matrix({"A", "B"}, 2, 2);
  const auto order = RenderingOrder(
      Pointers(runs), [](const RunSpec& r) { return std::optional<std::string>(r.dataset); });
  EXPECT_EQ(Ids(order), Ids(Pointers(runs)));  // already grouped: matrix order
}

TEST(RenderingOrderTest, RunsWithoutARenderingComeFirstAndAResumedStudyStartsWhereItStopped) {
  auto runs = Matrix({"A", "B", "C"}, 1, 2);
  // C is a recorded dataset (no rendering); A's first run finished in an earlier sitting.
  std::vector<const RunSpec*> pending;
  for (const auto& r : runs) {
    if (!(r.dataset == "A" && r.run == 0)) pending.push_back(&r);
  }
  const auto order = RenderingOrder(pending, [](const RunSpec& r) {
    return r.dataset == "C" ? std::nullopt
                            : std::optional<std::string>(fmt::format("{}{}", r.dataset, r.run));
  });
  const std::vector<std::string> expected = {"C/c0/seed1", "C/c0/seed2", "B/c0/seed1", "A/c0/seed2",
                                             "B/c0/seed2"};
  EXPECT_EQ(Ids(order), expected);
}

}  // namespace
}  // namespace pkslam::bench
