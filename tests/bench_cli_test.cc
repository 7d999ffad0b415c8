// End-to-end: `pkslam bench` runs the smoke suite (bench/suites/smoke.yaml: a rendered
// 5 s flight, stereo, orbslam3 vs pks vs pks with delta 40, 2 deterministic runs each), resumes
// without re-running, and the scale-out path (--emit-jobs, the jobs run by GNU parallel or sh,
// --collect) reproduces the same summary. Bad suites give one error line naming file:line.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

using testing::RunPkslam;

std::vector<std::string> Lines(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> out;
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

std::vector<std::string> Fields(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream ss(line);
  std::string f;
  while (std::getline(ss, f, ',')) fields.push_back(f);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

// summary.csv without the timing columns (wall time and tracking time differ run to run).
std::vector<std::string> SummaryWithoutTimes(const fs::path& file) {
  const auto lines = Lines(file);
  if (lines.empty()) return {};
  const auto header = Fields(lines[0]);
  std::vector<std::string> out;
  for (const auto& line : lines) {
    const auto fields = Fields(line);
    std::string joined;
    for (std::size_t i = 0; i < fields.size() && i < header.size(); ++i) {
      if (header[i] == "wall_mean_s" || header[i] == "median_tracking_mean_ms") continue;
      joined += fields[i] + ",";
    }
    out.push_back(joined);
  }
  return out;
}

// The report states one comparison once: the headline table's "mean of per-sequence changes" of
// `config` and the Statistics sentence on it carry the same signed number, and the report names
// one test (the permutation test on ranks), never a second one for the same comparison.
void ExpectOneSignAndOneTest(const std::string& report, const std::string& config) {
  std::vector<std::string> lines;
  std::stringstream in(report);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  auto cells = [](const std::string& row) {
    std::vector<std::string> out;
    std::stringstream cells_in(row);
    for (std::string cell; std::getline(cells_in, cell, '|');) {
      const auto b = cell.find_first_not_of(' ');
      const auto e = cell.find_last_not_of(' ');
      out.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
    }
    return out;
  };
  std::string headline;
  std::size_t column = 0;
  for (const std::string& line : lines) {
    if (line.rfind("| dataset |", 0) == 0 && column == 0) {
      const auto header = cells(line);
      column = static_cast<std::size_t>(std::find(header.begin(), header.end(), config) -
                                        header.begin());
    }
    if (line.rfind("| mean of per-sequence changes |", 0) == 0 && headline.empty()) {
      const auto row = cells(line);
      if (column < row.size()) headline = row[column];
    }
  }
  ASSERT_FALSE(headline.empty()) << report;
  const std::string lead = "- " + config + " vs ";
  std::string sentence;
  for (const std::string& line : lines) {
    if (line.rfind(lead, 0) == 0) sentence = line;
  }
  ASSERT_FALSE(sentence.empty()) << report;
  EXPECT_THAT(sentence, HasSubstr("ATE change " + headline + " ")) << headline << "\n" << sentence;
  EXPECT_THAT(report, HasSubstr("permutation test on ranks"));
  EXPECT_THAT(report, Not(HasSubstr("Mann-Whitney")));
  EXPECT_THAT(report, Not(HasSubstr("improvement")));
}

const fs::path kSmoke = fs::path(PKSLAM_SOURCE_DIR) / "bench/suites/smoke.yaml";

TEST(BenchCli, SmokeSuiteRunsResumesAndScalesOut) {
  const fs::path dir = testing::MakeTempDir("bench_smoke");
  const fs::path cache = dir / "cache";
  const fs::path out = dir / "local";
  auto r =
      RunPkslam(fmt::format("--log-level warn bench '{}' --out '{}' --cache '{}' --jobs 2 "
                            "--quiet",
                            kSmoke.string(), out.string(), cache.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("6 runs: 6 executed, 0 already finished, 0 failed"));
  const auto rows = Lines(out / "results.csv");
  ASSERT_EQ(rows.size(), 7u);  // header + 6 runs
  for (std::size_t i = 1; i < rows.size(); ++i) EXPECT_THAT(rows[i], HasSubstr(",ok,")) << rows[i];
  EXPECT_TRUE(fs::exists(out / "report.html"));
  EXPECT_TRUE(fs::exists(out / "report.md"));
  EXPECT_TRUE(fs::exists(out / "runs/sim_medium_5s/stereo/pks@delta=40/seed2/trajectory.txt"));
  if (fs::exists("/usr/bin/python3")) {
    EXPECT_TRUE(fs::exists(out / "plots/ate_bars.png")) << r.output;
    EXPECT_TRUE(fs::exists(out / "plots/sweep_delta.png")) << r.output;
  }
  // Each run has its viewer page, linked from the report; the report opens in headless
  // Chromium with every image loaded (tests/viewer/check_view.py).
  EXPECT_TRUE(fs::exists(out / "runs/sim_medium_5s/stereo/pks@delta=40/seed2/view.html"));
  EXPECT_TRUE(fs::exists(out / "viewer/three.min.js"));
  EXPECT_THAT(testing::ReadFileBytes(out / "report.html"),
              HasSubstr("runs/sim_medium_5s/stereo/pks@delta=40/seed2/view.html"));
  const auto opened = testing::RunCommand(
      fmt::format("/usr/bin/python3 '{}' report '{}'",
                  (fs::path(PKSLAM_SOURCE_DIR) / "tests/viewer/check_view.py").string(),
                  (out / "report.html").string()));
  EXPECT_EQ(opened.exit_code, 0) << opened.output;
  ExpectOneSignAndOneTest(testing::ReadFileBytes(out / "report.md"), "pks");
  // Runs write their keyframe trace by default (the views colour keyframes by rule), and their
  // segment errors, which the report draws as box plots.
  EXPECT_TRUE(fs::exists(out / "runs/sim_medium_5s/stereo/pks/seed1/keyframe_trace.csv"));
  EXPECT_TRUE(fs::exists(out / "runs/sim_medium_5s/stereo/pks/seed1/segment_errors.csv"));
  if (fs::exists("/usr/bin/python3")) {
    EXPECT_TRUE(fs::exists(out / "plots/segments_stereo.png")) << r.output;
  }

  // Resume: everything is finished, nothing runs again; --reevaluate measures the finished
  // runs again (same numbers: the same files and ground truth).
  const auto before = Lines(out / "results.csv");
  r = RunPkslam(fmt::format(
      "--log-level warn bench '{}' --out '{}' --cache '{}' --quiet --no-plots --reevaluate",
      kSmoke.string(), out.string(), cache.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("6 runs: 0 executed, 6 already finished"));
  EXPECT_EQ(Lines(out / "results.csv"), before);

  // The same suite asking for dense clouds of its sweep: only the two sweep runs get one
  // (pkslam dense on the finished runs), and the sweep table gains the Eq. 13 columns.
  {
    std::ifstream in(kSmoke);
    std::stringstream text;
    text << in.rdbuf();
    std::string yaml = text.str();
    const std::string sweep = "values: [40]}";
    ASSERT_NE(yaml.find(sweep), std::string::npos);
    yaml.replace(yaml.find(sweep), sweep.size(), "values: [40], dense: true}");
    std::ofstream(dir / "smoke_dense.yaml") << yaml;
  }
  r = RunPkslam(
      fmt::format("--log-level warn bench '{}' --out '{}' --cache '{}' --quiet --no-plots",
                  (dir / "smoke_dense.yaml").string(), out.string(), cache.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("6 runs: 2 executed, 4 already finished, 0 failed"));
  const fs::path sweep_run = out / "runs/sim_medium_5s/stereo/pks@delta=40/seed1";
  EXPECT_TRUE(fs::exists(sweep_run / "dense.ply"));
  EXPECT_FALSE(fs::exists(out / "runs/sim_medium_5s/stereo/pks/seed1/dense.ply"));
  const auto dense_rows = Lines(out / "results.csv");
  const auto columns = Fields(dense_rows.at(0));
  const auto dense_column = static_cast<std::size_t>(
      std::find(columns.begin(), columns.end(), "dense_points") - columns.begin());
  ASSERT_LT(dense_column, columns.size());
  int with_dense = 0;
  for (std::size_t i = 1; i < dense_rows.size(); ++i) {
    const auto f = Fields(dense_rows[i]);
    ASSERT_EQ(f.size(), columns.size()) << dense_rows[i];
    if (!f[dense_column].empty()) {
      ++with_dense;
      EXPECT_GT(std::stod(f[dense_column]), 1000.0) << dense_rows[i];
    }
  }
  EXPECT_EQ(with_dense, 2);
  std::ifstream report(out / "report.md");
  std::stringstream report_text;
  report_text << report.rdbuf();
  EXPECT_THAT(report_text.str(), HasSubstr("Eq. 13 score"));

  // Scale-out: emitted jobs run by GNU parallel (or sh without it), then --collect.
  const fs::path jobs = dir / "jobs";
  r = RunPkslam(fmt::format("bench '{}' --emit-jobs '{}' --cache '{}'",
                            (dir / "smoke_dense.yaml").string(), jobs.string(), cache.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("emitted 6 jobs"));
  ASSERT_EQ(Lines(jobs / "jobs.txt").size(), 6u);
  EXPECT_TRUE(fs::exists(jobs / "slurm.sh"));
  const bool have_parallel = testing::RunCommand("command -v parallel").exit_code == 0;
  const std::string runner = have_parallel ? "parallel --will-cite --jobs 2" : "sh";
  r = testing::RunCommand(fmt::format("{} < '{}'", runner, (jobs / "jobs.txt").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunPkslam(fmt::format("--log-level warn bench --collect '{}' --no-plots", jobs.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("collected 6 runs"));
  // Deterministic runs: the same numbers (dense clouds included) as the local bench.
  EXPECT_EQ(SummaryWithoutTimes(jobs / "summary.csv"), SummaryWithoutTimes(out / "summary.csv"));
}

// A study resumes from its recorded results.csv on a machine without its run folders: the
// recorded runs are not run again, the others are, and the collection holds both.
TEST(BenchCli, ResumesFromRecordedResultsWithoutTheRunFolders) {
  const fs::path dir = testing::MakeTempDir("bench_resume_from");
  const fs::path cache = dir / "cache";
  const std::string first = "sim_medium_5s/stereo/orbslam3/seed1";
  const std::string second = "sim_medium_5s/stereo/pks/seed1";
  auto r =
      RunPkslam(fmt::format("--log-level warn bench '{}' --out '{}' --cache '{}' --run-id {} "
                            "--quiet --no-plots",
                            kSmoke.string(), (dir / "a").string(), cache.string(), first));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunPkslam(fmt::format("--log-level warn bench --collect '{}' --no-plots --quiet",
                            (dir / "a").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path recorded = dir / "recorded.csv";  // what a study keeps in its repository
  const auto row_of = [](const fs::path& csv) {    // the row without its index
    const std::string line = Lines(csv).at(1);
    return line.substr(line.find(','));
  };
  fs::copy_file(dir / "a" / "results.csv", recorded);
  fs::remove_all(dir / "a");

  const std::string resume = fmt::format(
      "bench '{}' --out '{}' --cache '{}' --run-id {} --run-id {} --quiet --no-plots "
      "--resume-from '{}'",
      kSmoke.string(), (dir / "b").string(), cache.string(), first, second, recorded.string());
  r = RunPkslam(resume);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("1 finished runs imported"));
  EXPECT_THAT(r.output, HasSubstr("1 of 2 runs already finished: skipped"));
  EXPECT_EQ(row_of(dir / "b" / "runs" / first / "result.csv"), row_of(recorded))
      << "the recorded row, provenance included (only the index may differ)";
  // Measuring again keeps the imported numbers (there is no trajectory to measure).
  r = RunPkslam(resume + " --reevaluate");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("0 finished runs imported, 1 already here"));
  EXPECT_THAT(r.output, HasSubstr("2 of 2 runs already finished: skipped"));
  EXPECT_EQ(row_of(dir / "b" / "runs" / first / "result.csv"), row_of(recorded));
  r = RunPkslam(fmt::format("--log-level warn bench --collect '{}' --no-plots --quiet",
                            (dir / "b").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("collected 2 runs"));
  // The recorded collection merges with a folder's runs: here the first run only in the record,
  // the second only in the folder.
  fs::remove_all(dir / "b" / "runs" / first);
  r = RunPkslam(fmt::format("--log-level warn bench --collect '{}' '{}' --out '{}' --no-plots",
                            recorded.string(), (dir / "b").string(), (dir / "merged").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("collected 2 runs from 2 source(s)"));
  EXPECT_EQ(Lines(dir / "merged" / "results.csv").size(), 3u);

  r = RunPkslam(fmt::format("bench '{}' --out '{}' --run-id {} --resume-from '{}'", kSmoke.string(),
                            (dir / "c").string(), first, (dir / "missing.csv").string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr((dir / "missing.csv").string()));
}

// A study run in passes by different builds of pkslam renders with one build throughout
// (--simulator): the renderings are keyed by the simulator, the results record the build that ran.
TEST(BenchCli, TheSimulatorKeysTheRenderingsAndTheRunsRecordPkslam) {
  const fs::path dir = testing::MakeTempDir("bench_simulator");
  const fs::path cache = dir / "cache";
  // Another build of the simulator: the same program with a different hash.
  const fs::path simulator = dir / "pkslam-simulator";
  std::ofstream(simulator, std::ios::binary)
      << testing::ReadFileBytes(testing::PkslamExecutable()) << '\n';
  fs::permissions(simulator, fs::perms::owner_exec, fs::perm_options::add);
  const std::string run_id = "sim_medium_5s/stereo/orbslam3/seed1";
  auto bench = [&](const std::string& out, const std::string& extra) {
    return RunPkslam(
        fmt::format("--log-level warn bench '{}' --out '{}' --cache '{}' --run-id {} "
                    "--quiet {}",
                    kSmoke.string(), (dir / out).string(), cache.string(), run_id, extra));
  };
  auto renderings = [&] {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(cache)) {
      if (fs::exists(e.path() / ".complete")) names.push_back(e.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  };
  auto executable_of = [&](const std::string& out) {
    const auto lines = Lines(dir / out / "runs" / run_id / "result.csv");
    if (lines.size() < 2) return std::string();
    const auto header = Fields(lines[0]);
    const auto row = Fields(lines[1]);
    const auto at = std::find(header.begin(), header.end(), "executable") - header.begin();
    return static_cast<std::size_t>(at) < row.size() ? row[at] : std::string();
  };

  auto r = bench("a", "");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto first = renderings();
  ASSERT_EQ(first.size(), 1u);
  r = bench("b", fmt::format("--simulator '{}'", simulator.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto second = renderings();
  ASSERT_EQ(second.size(), 2u) << "the other simulator renders anew";
  const std::string added = second[0] == first[0] ? second[1] : second[0];
  EXPECT_THAT(testing::ReadFileBytes(cache / added / "recipe.txt"),
              StartsWith(simulator.string() + " simulate"));
  EXPECT_FALSE(executable_of("a").empty());
  EXPECT_EQ(executable_of("b"), executable_of("a")) << "both runs were made by pkslam";
  // The same simulator again: its rendering is found, nothing is rendered.
  r = bench("c", fmt::format("--simulator '{}'", simulator.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(renderings(), second);

  r = bench("d", fmt::format("--simulator '{}'", (dir / "missing").string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr((dir / "missing").string()));
}

// Every row records the commit of the pkslam that ran it: one built from a modified tree is
// named as such when the bench starts, not discovered in results.csv afterwards.
TEST(BenchCli, APkslamBuiltFromAModifiedTreeIsNamed) {
  const fs::path dir = testing::MakeTempDir("bench_dirty");
  const fs::path fake = dir / "pkslam-dirty";
  std::ofstream(fake) << "#!/bin/sh\necho 'pkslam 0.1.0 (commit 0123abc-dirty, Release)'\n";
  fs::permissions(fake, fs::perms::owner_exec, fs::perm_options::add);
  auto r = RunPkslam(fmt::format("bench '{}' --emit-jobs '{}' --pkslam '{}'", kSmoke.string(),
                                 (dir / "jobs").string(), fake.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("modified tree (commit 0123abc-dirty)"));
  // This test's own build, when it comes from a clean tree (CI's clone), is not named.
  if (RunPkslam("--version").output.find("-dirty") == std::string::npos) {
    r = RunPkslam(
        fmt::format("bench '{}' --emit-jobs '{}'", kSmoke.string(), (dir / "jobs2").string()));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, Not(HasSubstr("modified tree")));
  }
}

TEST(BenchCli, BadSuitesAreOneErrorLineWithFileAndLine) {
  const fs::path dir = testing::MakeTempDir("bench_bad");
  std::ofstream(dir / "bad.yaml") << "runs: 2\nselectors: [orbslam3]\nsensors: [stereo]\n"
                                     "datasets:\n  - {name: a, path: x, colour: red}\n";
  auto r = RunPkslam(
      fmt::format("bench '{}' --out '{}'", (dir / "bad.yaml").string(), (dir / "out").string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output, StartsWith("pkslam: error: "));
  EXPECT_THAT(r.output, HasSubstr("bad.yaml:5: unknown key 'colour'"));
  r = RunPkslam(fmt::format("bench '{}' --out x", (dir / "missing.yaml").string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output, HasSubstr("missing.yaml: cannot read the suite file"));
  r = RunPkslam(fmt::format("bench --collect '{}'", dir.string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output, HasSubstr("no runs/ folder"));
  // A dataset that does not exist fails its runs (recorded, reported) without aborting.
  std::ofstream(dir / "nodata.yaml") << "runs: 1\nselectors: [orbslam3]\nsensors: [stereo]\n"
                                        "datasets: [{name: a, path: no_such_dir}]\n";
  r = RunPkslam(fmt::format("--log-level error bench '{}' --out '{}' --quiet",
                            (dir / "nodata.yaml").string(), (dir / "out").string()));
  EXPECT_EQ(r.exit_code, 1) << r.output;  // every run failed: the sweep did not succeed
  EXPECT_THAT(r.output, Not(HasSubstr("plots unavailable")));  // no plots, but no crash either
  EXPECT_THAT(r.output, HasSubstr("1 runs: 1 executed, 0 already finished, 1 failed"));
  EXPECT_THAT(r.output, HasSubstr("pkslam: error: 1 of 1 runs failed"));
  EXPECT_THAT(Lines(dir / "out/results.csv").at(1), HasSubstr("no_such_dir is not a directory"));
}

// A peer system (here a stand-in script that "tracks" by copying the ground truth, like
// scripts/run_peer would write ORB-SLAM3's outputs) runs on the same rendering, is imported
// and evaluated like pkslam; a peer that crashes is a failed run with its last log line.
TEST(BenchCli, PeersRunBesidePkslam) {
  const fs::path dir = testing::MakeTempDir("bench_peer");
  {
    std::ofstream script(dir / "fake_peer.sh");
    script << "set -e\nout=$3\nmkdir -p \"$out\"\n"
              "if [ \"$2\" = stereo ]; then echo 'peer: crashed' >&2; exit 3; fi\n"
              "awk -F, '!/^#/ && NR % 20 == 2 {printf \"%.9f %s %s %s %s %s %s %s\\n\", $1/1e9, "
              "$2, $3, $4, $6, $7, $8, $5}' \"$1/mav0/state_groundtruth_estimate0/data.csv\" "
              "> \"$out/traj_tum.txt\"\nhead -3 \"$out/traj_tum.txt\" > \"$out/kf_tum.txt\"\n"
              "echo 'exit_status=0 wall_s=0.50' > \"$out/summary.txt\"\n";
  }
  {
    std::ofstream suite(dir / "peer.yaml");
    suite << "name: peer\nruns: 1\nseed: 1\ndeterministic: true\ntimeout_s: 300\n"
             "sensors: [stereo-inertial, stereo]\nselectors: [orbslam3]\n"
             "peers:\n  - {label: fake-peer, command: [/bin/sh, \"{suite_dir}/fake_peer.sh\", "
             "\"{dataset}\", \"{sensor}\", \"{out}\"]}\n"
             "datasets:\n  - name: flight\n    sim: {motion: medium, duration: 3, seed: 5, "
             "quality: fast, args: [--no-cloud]}\n";
  }
  const auto r = RunPkslam(
      fmt::format("--log-level warn bench '{}' --out '{}' --cache '{}' --quiet",
                  (dir / "peer.yaml").string(), (dir / "out").string(), (dir / "cache").string()));
  ASSERT_EQ(r.exit_code, 1) << r.output;  // the crashed peer run fails the sweep
  EXPECT_THAT(r.output, HasSubstr("4 runs: 4 executed, 0 already finished, 1 failed"));
  EXPECT_THAT(r.output, HasSubstr("pkslam: error: 1 of 4 runs failed"));
  EXPECT_TRUE(fs::exists(dir / "out/report.html"));  // the report is still written
  const auto rows = Lines(dir / "out/results.csv");
  ASSERT_EQ(rows.size(), 5u);
  const auto header = Fields(rows[0]);
  const auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  int peers_ok = 0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const auto f = Fields(rows[i]);
    if (f[column("config")] != "fake-peer") continue;
    if (f[column("sensor")] == "stereo") {
      EXPECT_EQ(f[column("status")], "failed") << rows[i];
      EXPECT_THAT(rows[i], HasSubstr("peer: crashed"));
      continue;
    }
    EXPECT_EQ(f[column("status")], "ok") << rows[i];
    EXPECT_LT(std::stod(f[column("ate_se3_rmse_m")]), 1e-6) << rows[i];   // the truth itself
    EXPECT_NEAR(std::stod(f[column("coverage")]), 0.5, 0.05) << rows[i];  // every 2nd frame
    EXPECT_EQ(f[column("keyframes")], "3");
    ++peers_ok;
  }
  EXPECT_EQ(peers_ok, 1);
  EXPECT_TRUE(fs::exists(dir / "out/runs/flight/stereo-inertial/fake-peer/seed1/stats.json"));
  EXPECT_TRUE(fs::exists(dir / "out/report.md"));
}

}  // namespace
}  // namespace pkslam
