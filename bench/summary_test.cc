#include "bench/summary.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pkslam::bench {
namespace {

RunResult Result(int index, const std::string& dataset, const std::string& config, double ate,
                 int keyframes, bool ok = true) {
  RunResult r;
  r.index = index;
  r.run_id = dataset + "/stereo/" + config + "/seed" + std::to_string(index);
  r.dataset = dataset;
  r.sensor = "stereo";
  r.config = config;
  r.selector = config;
  r.baseline = "orbslam3";
  r.alignment = "se3";
  r.ok = ok;
  r.ate_m = ok ? ate : kNaN;
  r.keyframes = keyframes;
  r.coverage = 1.0;
  return r;
}

TEST(Summary, MeanAndSampleStd) {
  const MeanStd m = ComputeMeanStd({1.0, 2.0, 3.0, kNaN});
  EXPECT_EQ(m.n, 3);
  EXPECT_DOUBLE_EQ(m.mean, 2.0);
  EXPECT_DOUBLE_EQ(m.std, 1.0);
  EXPECT_EQ(ComputeMeanStd({}).n, 0);
  EXPECT_DOUBLE_EQ(ComputeMeanStd({5.0}).std, 0.0);
}

TEST(Summary, ASpreadOfZeroSaysTheRunsWereIdentical) {
  EXPECT_EQ(FormatMeanStd(ComputeMeanStd({0.0123, 0.0123, 0.0123}), 4),
            "0.0123 (3 identical runs)");
  EXPECT_EQ(FormatMeanStd(ComputeMeanStd({0.0123}), 4), "0.0123 (1 run)");
  EXPECT_EQ(FormatMeanStd(ComputeMeanStd({0.01, 0.02}), 3), "0.015 ± 0.007");
  EXPECT_EQ(FormatMeanStd(ComputeMeanStd({}), 3), "—");
}

TEST(Summary, GroupsInMatrixOrderWithTheAteChangeAgainstTheBaseline) {
  // Deliberately shuffled input; failed runs count in runs but not in the statistics.
  const std::vector<RunResult> results = {
      Result(3, "A", "pks", 0.08, 30),      Result(0, "A", "orbslam3", 0.10, 50),
      Result(1, "A", "orbslam3", 0.10, 52), Result(2, "A", "pks", 0.07, 28),
      Result(5, "A", "pks", 0.0, 0, false), Result(6, "B", "orbslam3", 0.2, 10),
      Result(7, "B", "pks", 0.3, 9)};
  const auto groups = Summarize(results);
  ASSERT_EQ(groups.size(), 4u);
  EXPECT_EQ(groups[0].config, "orbslam3");
  EXPECT_EQ(groups[1].config, "pks");
  EXPECT_EQ(groups[1].runs, 3);
  EXPECT_EQ(groups[1].ok, 2);
  EXPECT_NEAR(groups[1].ate_m.mean, 0.075, 1e-12);
  EXPECT_NEAR(groups[1].keyframes.mean, 29.0, 1e-12);
  EXPECT_NEAR(groups[1].ate_change_pct, -25.0, 1e-9);  // (0.075 - 0.10) / 0.10: lower
  EXPECT_NEAR(groups[3].ate_change_pct, 50.0, 1e-9);   // higher than the baseline's
  EXPECT_NEAR(groups[0].ate_change_pct, 0.0, 1e-12);

  const auto tables = HeadlineTables(groups);
  ASSERT_EQ(tables.size(), 1u);
  ASSERT_EQ(tables[0].header, (std::vector<std::string>{"dataset", "orbslam3", "pks"}));
  ASSERT_EQ(tables[0].rows.size(), 5u);  // A, B, mean ATE, mean change, wins
  EXPECT_EQ(tables[0].rows[0][2], "0.0750 ± 0.0071 (-25.0%) [2/3 ok]");
  EXPECT_EQ(tables[0].rows[2][1], "0.1500");
  EXPECT_EQ(tables[0].rows[2][2], "0.1875 (+25.0%)");  // (0.1875 - 0.15) / 0.15
  EXPECT_EQ(tables[0].rows[3][2], "+12.5%");
  EXPECT_EQ(tables[0].rows[4][2], "1/2");
  EXPECT_EQ(FailureTable(results).rows.size(), 1u);
  // Every table's rows are as wide as its header (a missing header cell shifts the columns).
  const Table detail = DetailTable(groups);
  for (const auto& row : detail.rows) EXPECT_EQ(row.size(), detail.header.size());
  EXPECT_EQ(detail.header[7], "coverage");
  EXPECT_EQ(detail.rows[0][7], "100%");

  // A configuration tracking only part of the sequence is flagged.
  auto partial = results;
  for (auto& r : partial) {
    if (r.dataset == "B" && r.config == "pks") r.coverage = 0.25;
  }
  EXPECT_EQ(HeadlineTables(Summarize(partial))[0].rows[1][2], "0.3000 (1 run) (+50.0%) [cov 25%]");
  const std::string md = MarkdownTable(tables[0]);
  EXPECT_NE(md.find("| dataset | orbslam3 | pks |"), std::string::npos) << md;
}

RunResult Timed(int index, const std::string& config, double realtime_factor, double tracking_ms,
                double cpu_s, bool ok = true) {
  RunResult r = Result(index, "A", config, 0.1, 20, ok);
  r.realtime_factor = realtime_factor;
  r.median_tracking_ms = tracking_ms;
  r.p95_tracking_ms = 2 * tracking_ms;
  r.mapping_ms_per_kf = 10 * tracking_ms;
  r.cpu_s = cpu_s;
  r.peak_memory_mib = 100 * cpu_s;
  return r;
}

// Speed cells are medians over the successful runs; the peer column is the ratio of realtime
// factors on the same dataset and sensor.
TEST(Summary, SpeedTableHoldsMediansAndThePeerRatio) {
  std::vector<RunResult> results = {
      Timed(0, "orbslam3", 2.0, 20.0, 30.0),      Timed(1, "orbslam3", 4.0, 10.0, 50.0),
      Timed(2, "orbslam3", 3.0, 12.0, 40.0),      Timed(3, "orbslam3", 100.0, 1.0, 1.0, false),
      Timed(4, "orbslam3-peer", 1.5, 25.0, 60.0), Timed(5, "orbslam3-peer", 0.5, 35.0, 80.0),
      Timed(6, "pks", kNaN, kNaN, kNaN)};
  results[4].selector = results[5].selector = "peer";
  const Table t = SpeedTable(Summarize(results));
  ASSERT_EQ(t.rows.size(), 3u);
  ASSERT_EQ(t.header.size(), 11u);
  EXPECT_EQ(t.header[4], "realtime factor");
  EXPECT_EQ(t.header.back(), "RT pkslam/orbslam3-peer");
  for (const auto& row : t.rows) EXPECT_EQ(row.size(), t.header.size());
  // orbslam3: 3 of 4 runs ok; the failed run's 100x does not count.
  EXPECT_EQ(t.rows[0], (std::vector<std::string>{"A", "stereo", "orbslam3", "3/4", "3.00", "12.0",
                                                 "24.0", "120.0", "40.0", "4000", "3.00"}));
  // The peer: median of two runs is their mean; no ratio against itself.
  EXPECT_EQ(t.rows[1][4], "1.00");
  EXPECT_EQ(t.rows[1][5], "30.0");
  EXPECT_EQ(t.rows[1].back(), "");
  // A configuration without speed measures shows dashes and no ratio.
  EXPECT_EQ(t.rows[2][4], "—");
  EXPECT_EQ(t.rows[2][9], "—");
  EXPECT_EQ(t.rows[2].back(), "");

  // Without a peer there is no ratio column; without realtime factors no table.
  results.resize(4);
  EXPECT_EQ(SpeedTable(Summarize(results)).header.back(), "peak memory [MiB]");
  for (auto& r : results) r.realtime_factor = kNaN;
  EXPECT_TRUE(SpeedTable(Summarize(results)).rows.empty());
}

// Eq. 13: density and ATE normalised over the sweep, the largest density - ATE wins.
TEST(Summary, SweepScoreFollowsEquation13) {
  std::vector<RunResult> results;
  const double deltas[] = {10, 20, 30};
  const double ates[] = {0.010, 0.020, 0.012};
  const double dense[] = {1000, 3000, 2500};
  for (int i = 0; i < 3; ++i) {
    RunResult r =
        Result(i, "V1", "pks@delta=" + std::to_string(static_cast<int>(deltas[i])), ates[i], 20);
    r.selector = "pks";
    r.sweep_param = "delta";
    r.sweep_value = deltas[i];
    r.dense_points = dense[i];
    results.push_back(r);
  }
  const auto groups = Summarize(results);
  ASSERT_EQ(groups.size(), 3u);
  EXPECT_NEAR(groups[0].sweep_score, 0.0 - 0.0, 1e-12);   // fewest points, best ATE
  EXPECT_NEAR(groups[1].sweep_score, 1.0 - 1.0, 1e-12);   // most points, worst ATE
  EXPECT_NEAR(groups[2].sweep_score, 0.75 - 0.2, 1e-12);  // the paper's choice here
  const auto tables = SweepTables(groups);
  ASSERT_EQ(tables.size(), 1u);
  ASSERT_EQ(tables[0].header.back(), "Eq. 13 score");
  EXPECT_EQ(tables[0].rows[2].back(), "+0.55 (best)");
  EXPECT_EQ(tables[0].rows[0].back(), "+0.00");
  // Without dense clouds there is no score and no extra columns.
  for (auto& r : results) r.dense_points = kNaN;
  const auto plain = Summarize(results);
  EXPECT_TRUE(std::isnan(plain[2].sweep_score));
  EXPECT_EQ(SweepTables(plain)[0].header.back(), "ok/runs");
}

// A swept parameter that changed nothing (same keyframes and ATE at every value) is named in the
// sweep's table instead of plotting as a flat line without a word.
TEST(Summary, ASweepWhoseParameterDidNotActIsSaidSo) {
  std::vector<RunResult> results;
  for (int i = 0; i < 3; ++i) {
    for (const char* selector : {"pks", "orbslam3"}) {
      const bool acts = std::string(selector) == "pks";
      RunResult r = Result(static_cast<int>(results.size()), "V1",
                           std::string(selector) + "@tau=" + std::to_string(i),
                           acts ? 0.01 * (i + 1) : 0.02, acts ? 20 + i : 30);
      r.selector = selector;
      r.sweep_param = "tau";
      r.sweep_value = i;
      results.push_back(r);
    }
  }
  const auto tables = SweepTables(Summarize(results));
  ASSERT_EQ(tables.size(), 1u);
  EXPECT_NE(tables[0].title.find("no value of tau changed the runs of V1/"), std::string::npos)
      << tables[0].title;
  EXPECT_NE(tables[0].title.find("/orbslam3"), std::string::npos) << tables[0].title;
  EXPECT_EQ(tables[0].title.find("/pks"), std::string::npos) << tables[0].title;
}

TEST(Summary, ReasonTableCountsEveryRuleAKeyframeNames) {
  RunResult a = Result(0, "d", "pks-released", 0.01, 20);
  a.keyframe_reasons = "forced=10 forced+imu=2 camera;busy=1";
  RunResult b = Result(1, "d", "pks-released", 0.01, 20);
  b.keyframe_reasons = "forced=6 imu=2";
  RunResult peer = Result(2, "d", "orbslam3-peer", 0.01, 20);  // no reasons: no row
  const Table t = ReasonTable({a, b, peer});
  ASSERT_EQ(t.rows.size(), 1u);
  EXPECT_EQ(t.header, (std::vector<std::string>{"sensor", "configuration", "runs", "forced", "imu",
                                                "camera"}));
  // forced: (12 + 6) / 2 runs = 9 per run, 18 of 23 mentions; imu (2 + 2) / 2; camera 1 / 2.
  EXPECT_EQ(t.rows[0][3], "9.0 (78%)");
  EXPECT_EQ(t.rows[0][4], "2.0 (17%)");
  EXPECT_EQ(t.rows[0][5], "0.5 (4%)");
}

}  // namespace
}  // namespace pkslam::bench
