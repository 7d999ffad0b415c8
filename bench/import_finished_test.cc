#include "bench/import_finished.h"

#include <gtest/gtest.h>

#include <fstream>

#include "bench/executor.h"
#include "bench/results.h"
#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

RunSpec Spec(int index, const std::string& config, int run) {
  RunSpec s;
  s.index = index;
  s.dataset = "flight";
  s.sensor = "stereo-inertial";
  s.config = config;
  s.run = run;
  s.seed = static_cast<std::uint64_t>(run + 1);
  s.id = "flight/stereo-inertial/" + config + "/seed" + std::to_string(run + 1);
  return s;
}

RunResult Recorded(const RunSpec& s, double ate_m, const std::string& executable) {
  RunResult r;
  r.index = 100 + s.index;  // the old collection's numbering
  r.run_id = s.id;
  r.dataset = s.dataset;
  r.sensor = s.sensor;
  r.config = s.config;
  r.seed = s.seed;
  r.ok = true;
  r.ate_m = ate_m;
  r.provenance.executable = executable;
  return r;
}

TEST(ImportFinished, RecordedRunsBecomeFinishedRunsWithTheirProvenance) {
  const fs::path dir = testing::MakeTempDir("import_finished");
  const std::vector<RunSpec> runs = {Spec(0, "pks", 0), Spec(1, "orbslam3", 0), Spec(2, "pks", 1)};
  const RunSpec other = Spec(3, "interval", 0);  // recorded, but not selected now
  WriteResultsCsv(dir / "results.csv",
                  {Recorded(runs[0], 0.021, "old-build"), Recorded(runs[1], 0.034, "old-build"),
                   Recorded(other, 0.5, "old-build")});
  const fs::path out = dir / "out";
  // An interrupted run of the first: its leftovers go, the record replaces them.
  fs::create_directories(RunDir(out, runs[0]));
  std::ofstream(RunDir(out, runs[0]) / "trajectory.txt") << "partial\n";

  const ImportCounts counts = ImportFinished(dir / "results.csv", runs, out);
  EXPECT_EQ(counts.imported, 2);
  EXPECT_EQ(counts.present, 0);
  EXPECT_EQ(counts.other, 1);
  const auto first = ReadFinished(RunDir(out, runs[0]));
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->index, 0) << "the run's place in this suite";
  EXPECT_DOUBLE_EQ(first->ate_m, 0.021);
  EXPECT_EQ(first->provenance.executable, "old-build") << "the build that made it";
  EXPECT_TRUE(IsImported(RunDir(out, runs[0])));
  EXPECT_FALSE(fs::exists(RunDir(out, runs[0]) / "trajectory.txt"));
  EXPECT_FALSE(ReadFinished(RunDir(out, runs[2])).has_value()) << "not recorded: still to run";
  EXPECT_FALSE(fs::exists(RunDir(out, other)));

  // A run measured here since then is not overwritten by the record.
  RunResult measured = Recorded(runs[1], 0.040, "new-build");
  measured.index = runs[1].index;
  fs::remove(RunDir(out, runs[1]) / "imported");
  WriteResultsCsv(RunDir(out, runs[1]) / "result.csv", {measured});
  const ImportCounts again = ImportFinished(dir / "results.csv", runs, out);
  EXPECT_EQ(again.imported, 0);
  EXPECT_EQ(again.present, 2);
  EXPECT_DOUBLE_EQ(ReadFinished(RunDir(out, runs[1]))->ate_m, 0.040);
  EXPECT_FALSE(IsImported(RunDir(out, runs[1])));
}

TEST(ImportFinished, ARecordOfAnotherSuiteIsRefusedNamingTheFile) {
  const fs::path dir = testing::MakeTempDir("import_finished_other");
  const RunSpec run = Spec(0, "pks", 0);
  RunResult row = Recorded(run, 0.02, "b");
  row.sensor = "stereo";  // same id, different run
  WriteResultsCsv(dir / "results.csv", {row});
  try {
    ImportFinished(dir / "results.csv", {run}, dir / "out");
    FAIL() << "no error for a contradicting row";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), dir / "results.csv");
    EXPECT_NE(std::string(e.what()).find(run.id), std::string::npos) << e.what();
  }
  EXPECT_THROW(ImportFinished(dir / "missing.csv", {run}, dir / "out"), InputError);
}

}  // namespace
}  // namespace pkslam::bench
