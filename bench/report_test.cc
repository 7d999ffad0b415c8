#include "bench/report.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "tests/support/test_data.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

std::string ReadText(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

RunResult TimedRun(int index, double realtime_factor) {
  RunSpec spec;
  spec.index = index;
  spec.dataset = "A";
  spec.sensor = "stereo";
  spec.config = spec.selector = "orbslam3";
  spec.id = spec.dataset + "/" + spec.sensor + "/" + spec.config + "/seed" + std::to_string(index);
  RunResult r = ResultSkeleton(spec, Suite{});
  r.ok = true;
  r.ate_m = 0.1;
  r.coverage = 1.0;
  r.realtime_factor = realtime_factor;
  return r;
}

// The Speed section appears (Markdown and HTML) only when runs measured a realtime factor, so
// reports of older runs do not gain an empty table.
TEST(Report, SpeedSectionOnlyWithRealtimeFactors) {
  const fs::path dir = testing::MakeTempDir("bench_report_speed");
  ReportOptions options;
  options.plots = false;
  options.out = dir / "timed";
  WriteReport({TimedRun(0, 2.0), TimedRun(1, 4.0)}, options);
  const std::string md = ReadText(options.out / "report.md");
  EXPECT_NE(md.find("## Speed"), std::string::npos) << md;
  EXPECT_NE(md.find("| A | stereo | orbslam3 | 2/2 | 3.00 |"), std::string::npos) << md;
  EXPECT_NE(ReadText(options.out / "report.html").find("<h2>Speed</h2>"), std::string::npos);

  options.out = dir / "untimed";
  WriteReport({TimedRun(0, kNaN), TimedRun(1, kNaN)}, options);
  EXPECT_EQ(ReadText(options.out / "report.md").find("## Speed"), std::string::npos);
}

}  // namespace
}  // namespace pkslam::bench
