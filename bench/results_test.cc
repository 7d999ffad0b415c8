#include "bench/results.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam::bench {
namespace {

TEST(ResultsCsv, QuotesFieldsWithCommasAndQuotes) {
  EXPECT_EQ(CsvField("plain"), "plain");
  EXPECT_EQ(CsvField("a,b"), "\"a,b\"");
  EXPECT_EQ(CsvField("say \"hi\""), "\"say \"\"hi\"\"\"");
  const auto f = SplitCsvLine("1,\"a,b\",\"say \"\"hi\"\"\",,x");
  ASSERT_EQ(f.size(), 5u);
  EXPECT_EQ(f[1], "a,b");
  EXPECT_EQ(f[2], "say \"hi\"");
  EXPECT_EQ(f[3], "");
}

TEST(ResultsCsv, RoundTripsEveryField) {
  RunSpec spec;
  spec.index = 4;
  spec.id = "d/mono/pks@delta_deg=20/seed3";
  spec.dataset = "d";
  spec.sensor = "mono";
  spec.config = "pks@delta_deg=20";
  spec.selector = "pks";
  spec.params = {{"delta_deg", 20}, {"tau", 0.25}};
  spec.sweep_param = "delta_deg";
  spec.sweep_value = 20;
  spec.seed = 3;
  Suite suite;
  RunResult ok = ResultSkeleton(spec, suite);
  EXPECT_EQ(ok.alignment, "sim3");  // monocular
  ok.ok = true;
  ok.ate_m = 0.0123;
  ok.ate_se3_m = 0.5;
  ok.ate_sim3_m = 0.0123;
  ok.scale = 0.87;
  ok.keyframes = 42;
  ok.map_points = 1234;
  ok.lost_frames = 2;
  ok.frames = 200;
  ok.wall_s = 12.5;
  ok.median_tracking_ms = 20.25;
  ok.dense_points = 123456;
  ok.accel_bias_err_pct = 12.5;
  ok.realtime_factor = 1.75;
  ok.p95_tracking_ms = 31.5;
  ok.mapping_ms_per_kf = 48.25;
  ok.cpu_s = 60.5;
  ok.peak_memory_mib = 812;
  RunResult failed = ok;
  failed.index = 5;
  failed.run_id = "d/mono/pks/seed4";
  failed.ok = false;
  failed.error = "pkslam run exit 1: bad, \"quoted\" input";
  failed.ate_m = kNaN;
  const auto dir = testing::MakeTempDir("bench_results");
  WriteResultsCsv(dir / "results.csv", {ok, failed});
  const auto back = ReadResultsCsv(dir / "results.csv");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].run_id, ok.run_id);
  EXPECT_EQ(back[0].params, "delta_deg=20;tau=0.25");
  EXPECT_EQ(back[0].sweep_value, 20.0);
  EXPECT_TRUE(back[0].ok);
  EXPECT_DOUBLE_EQ(back[0].ate_m, 0.0123);
  EXPECT_DOUBLE_EQ(back[0].scale, 0.87);
  EXPECT_EQ(back[0].keyframes, 42);
  EXPECT_EQ(back[0].map_points, 1234);
  EXPECT_DOUBLE_EQ(back[0].median_tracking_ms, 20.25);
  EXPECT_DOUBLE_EQ(back[0].dense_points, 123456);
  EXPECT_DOUBLE_EQ(back[0].accel_bias_err_pct, 12.5);
  EXPECT_TRUE(std::isnan(back[0].gyro_bias_err_pct));
  EXPECT_TRUE(std::isnan(back[0].rpe_trans_m));
  EXPECT_DOUBLE_EQ(back[0].realtime_factor, 1.75);
  EXPECT_DOUBLE_EQ(back[0].p95_tracking_ms, 31.5);
  EXPECT_DOUBLE_EQ(back[0].mapping_ms_per_kf, 48.25);
  EXPECT_DOUBLE_EQ(back[0].cpu_s, 60.5);
  EXPECT_DOUBLE_EQ(back[0].peak_memory_mib, 812);
  EXPECT_FALSE(back[1].ok);
  EXPECT_EQ(back[1].error, failed.error);
  EXPECT_TRUE(std::isnan(back[1].ate_m));
}

// keyframes_created and the provenance columns, the last ones added.
constexpr int kProvenance = 7;

// result.csv of `r` as written by a version without the last `dropped` columns.
std::vector<RunResult> ReadWithoutTrailingColumns(const RunResult& r, int dropped,
                                                  const std::string& name) {
  std::string header = ResultCsvHeader();
  std::string row = ResultCsvRow(r);
  for (int k = 0; k < dropped; ++k) {
    header = header.substr(0, header.rfind(','));
    row = row.substr(0, row.rfind(','));
  }
  const auto dir = testing::MakeTempDir(name);
  std::ofstream(dir / "result.csv") << header << '\n' << row << '\n';
  return ReadResultsCsv(dir / "result.csv");
}

RunResult MeasuredRun() {
  RunResult r;
  r.run_id = "d/stereo/pks/seed1";
  r.ok = true;
  r.ate_m = 0.01;
  r.dense_points = 5;
  r.gyro_bias_err_pct = 7;
  r.realtime_factor = 2.5;
  r.cpu_s = 12;
  return r;
}

// result.csv files of runs finished before the optional trailing columns still read (a resumed or
// collected bench must not run them again).
TEST(ResultsCsv, ReadsFilesWithoutTheDenseColumn) {
  // dense_points, the bias errors, the 5 speed columns and the 5 study columns came later.
  const auto back =
      ReadWithoutTrailingColumns(MeasuredRun(), 13 + kProvenance, "bench_results_legacy");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_TRUE(back[0].ok);
  EXPECT_DOUBLE_EQ(back[0].ate_m, 0.01);
  EXPECT_TRUE(std::isnan(back[0].dense_points));
  EXPECT_TRUE(std::isnan(back[0].realtime_factor));
}

TEST(ResultsCsv, ReadsFilesWithoutTheSpeedColumns) {
  const auto back =
      ReadWithoutTrailingColumns(MeasuredRun(), 10 + kProvenance, "bench_results_no_speed");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_DOUBLE_EQ(back[0].dense_points, 5);  // the older optional columns still read
  EXPECT_DOUBLE_EQ(back[0].gyro_bias_err_pct, 7);
  EXPECT_TRUE(std::isnan(back[0].realtime_factor));
  EXPECT_TRUE(std::isnan(back[0].cpu_s));
  EXPECT_TRUE(std::isnan(back[0].peak_memory_mib));
  // Only the speed columns a file has are read: with realtime_factor, without cpu_s.
  const auto partial =
      ReadWithoutTrailingColumns(MeasuredRun(), 9 + kProvenance, "bench_results_part_speed");
  EXPECT_DOUBLE_EQ(partial[0].realtime_factor, 2.5);
  EXPECT_TRUE(std::isnan(partial[0].cpu_s));
}

TEST(ResultsCsv, SpeedColumnsTrailTheOlderOptionalOnes) {
  const auto columns = ResultColumns();
  const std::vector<std::string> tail(columns.end() - 11 - kProvenance,
                                      columns.end() - kProvenance);
  EXPECT_EQ(tail,
            (std::vector<std::string>{"accel_bias_err_pct", "realtime_factor", "p95_tracking_ms",
                                      "mapping_ms_per_kf", "cpu_s", "peak_memory_mib", "sequence_s",
                                      "mapping_cpu_s", "degraded", "keyframe_reasons", "suspect"}));
}

TEST(ResultsCsv, StudyColumnsRoundTripAndOlderFilesLackThem) {
  RunResult r = MeasuredRun();
  r.sequence_s = 60;
  r.mapping_cpu_s = 21.5;
  r.degraded = 1;
  r.keyframe_reasons = "camera=3 forced+imu=2 time=40";
  r.suspect = 1;
  const auto back = ReadWithoutTrailingColumns(r, 0, "bench_results_study");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_DOUBLE_EQ(back[0].mapping_cpu_s, 21.5);
  EXPECT_DOUBLE_EQ(back[0].degraded, 1.0);
  EXPECT_EQ(back[0].keyframe_reasons, "camera=3 forced+imu=2 time=40");
  EXPECT_DOUBLE_EQ(back[0].suspect, 1.0);
  // Files from before the suspect column keep their keyframe reasons.
  const auto no_suspect =
      ReadWithoutTrailingColumns(r, 1 + kProvenance, "bench_results_no_suspect");
  EXPECT_EQ(no_suspect[0].keyframe_reasons, "camera=3 forced+imu=2 time=40");
  EXPECT_TRUE(std::isnan(no_suspect[0].suspect));
  const auto older = ReadWithoutTrailingColumns(r, 5 + kProvenance, "bench_results_no_study");
  EXPECT_DOUBLE_EQ(older[0].cpu_s, 12.0);
  EXPECT_TRUE(std::isnan(older[0].sequence_s));
  EXPECT_TRUE(older[0].keyframe_reasons.empty());
}

TEST(ResultsCsv, ProvenanceRoundTripsAndOlderFilesLackIt) {
  RunResult r = MeasuredRun();
  r.provenance.pkslam_commit = "0ba4feb1c2d3e4f5a6b7c8d9e0f1a2b3c4d5e6f7-dirty";
  r.provenance.executable = "89ab01cd23ef4567";
  r.provenance.peer_build = "pks a6a7dc5 libORB_SLAM3.so=1234abcd";
  r.provenance.cores = 2;
  r.provenance.jobs = 1;
  r.provenance.finished_utc = "2026-11-30T01:02:03Z";
  r.keyframes_created = 195;
  const auto columns = ResultColumns();
  EXPECT_EQ(std::vector<std::string>(columns.end() - kProvenance, columns.end()),
            (std::vector<std::string>{"keyframes_created", "pkslam_commit", "executable",
                                      "peer_build", "cores", "jobs", "finished_utc"}));
  const auto back = ReadWithoutTrailingColumns(r, 0, "bench_results_provenance");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].provenance.pkslam_commit, r.provenance.pkslam_commit);
  EXPECT_EQ(back[0].provenance.executable, r.provenance.executable);
  EXPECT_EQ(back[0].provenance.peer_build, r.provenance.peer_build);
  EXPECT_EQ(back[0].provenance.cores, 2);
  EXPECT_EQ(back[0].provenance.jobs, 1);
  EXPECT_EQ(back[0].provenance.finished_utc, r.provenance.finished_utc);
  EXPECT_DOUBLE_EQ(back[0].keyframes_created, 195);
  // Files from before provenance: the suspect column is the last, the provenance empty.
  const auto older = ReadWithoutTrailingColumns(r, kProvenance, "bench_results_no_provenance");
  EXPECT_DOUBLE_EQ(older[0].ate_m, 0.01);
  EXPECT_TRUE(older[0].provenance.pkslam_commit.empty());
  EXPECT_TRUE(std::isnan(older[0].keyframes_created));
  EXPECT_EQ(older[0].provenance.cores, 0);
  // Unknown counts are written empty and read back as 0.
  r.provenance.cores = 0;
  EXPECT_EQ(ReadWithoutTrailingColumns(r, 0, "bench_results_no_cores")[0].provenance.cores, 0);
}

TEST(ResultsCsv, MalformedFilesNameTheLine) {
  const auto dir = testing::MakeTempDir("bench_results_bad");
  {
    std::ofstream(dir / "wrong_header.csv") << "a,b\n";
    std::ofstream(dir / "short_row.csv") << ResultCsvHeader() << "\n1,2,3\n";
    std::ofstream(dir / "empty.csv");
  }
  try {
    ReadResultsCsv(dir / "short_row.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 2u);
  }
  EXPECT_THROW(ReadResultsCsv(dir / "wrong_header.csv"), InputError);
  EXPECT_THROW(ReadResultsCsv(dir / "empty.csv"), InputError);
  EXPECT_THROW(ReadResultsCsv(dir / "missing.csv"), InputError);
}

}  // namespace
}  // namespace pkslam::bench
