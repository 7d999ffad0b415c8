#include "bench/suite.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <fstream>
#include <set>

#include "bench/executor.h"
#include "bench/matrix.h"
#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

const char* kSuite = R"(name: demo
runs: 3
seed: 10
sensors: [stereo, mono]
selectors:
  - orbslam3
  - {name: pks, params: {tau: 0.5}}
params: {Keyframe.min_frames: 2}
sweeps:
  - {selector: pks, param: delta_deg, values: [10, 20]}
datasets:
  - {name: real, path: data/real}
  - name: only_stereo
    path: /abs/path
    sensors: [stereo]
)";

// Expects ParseSuite(text) to throw InputError on `line` whose message contains `what`.
void ExpectError(const std::string& text, std::size_t line, const std::string& what) {
  try {
    ParseSuite(text, "dir/suite.yaml");
    FAIL() << "no error for:\n" << text;
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("dir/suite.yaml"), std::string::npos) << e.what();
  }
}

TEST(Suite, ParsesAllFields) {
  const Suite s = ParseSuite(kSuite, "dir/suite.yaml");
  EXPECT_EQ(s.name, "demo");
  EXPECT_EQ(s.runs, 3);
  EXPECT_EQ(s.seed, 10u);
  ASSERT_EQ(s.selectors.size(), 2u);
  EXPECT_EQ(s.selectors[1].label, "pks");
  EXPECT_EQ(s.selectors[1].params.at("tau"), 0.5);
  EXPECT_EQ(s.params.at("min_frames"), 2.0);  // Keyframe. prefix dropped
  ASSERT_EQ(s.datasets.size(), 2u);
  EXPECT_EQ(*s.datasets[0].path, std::filesystem::absolute("dir/data/real"));
  EXPECT_EQ(*s.datasets[1].path, std::filesystem::path("/abs/path"));
}

// Repeated runs must differ by more than thread timing: each passes its own --seed to run.
TEST(Suite, RunArgumentsCarryTheRunSeed) {
  const Suite s = ParseSuite(kSuite, "dir/suite.yaml");
  const auto runs = ExpandSuite(s);
  for (int k = 0; k < 3; ++k) {
    const auto a = RunArguments(s, runs[static_cast<std::size_t>(k)], "data", "out");
    const auto it = std::find(a.begin(), a.end(), "--seed");
    ASSERT_NE(it, a.end());
    ASSERT_NE(it + 1, a.end());
    EXPECT_EQ(*(it + 1), std::to_string(10 + k));
  }
}

// Every run writes its keyframe trace unless the suite says trace: false (the viewer colours
// keyframes by rule from it).
TEST(Suite, RunsWriteTheirTraceByDefault) {
  const Suite s = ParseSuite(kSuite, "dir/suite.yaml");
  const auto runs = ExpandSuite(s);
  auto has_trace = [](const std::vector<std::string>& a) {
    return std::find(a.begin(), a.end(), "--trace") != a.end();
  };
  EXPECT_TRUE(has_trace(RunArguments(s, runs[0], "data", "out")));
  const Suite quiet = ParseSuite(std::string(kSuite) + "trace: false\n", "dir/suite.yaml");
  EXPECT_FALSE(has_trace(RunArguments(quiet, ExpandSuite(quiet)[0], "data", "out")));
}

TEST(Suite, DenseCloudsForTheSweepOrTheWholeSuite) {
  std::string text = kSuite;
  text.replace(text.find("values: [10, 20]}"), 17, "values: [10, 20], dense: true}");
  const Suite s = ParseSuite(text, "dir/suite.yaml");
  ASSERT_TRUE(s.sweeps[0].dense);
  const auto runs = ExpandSuite(s);
  EXPECT_FALSE(runs[0].dense);               // real/stereo/orbslam3
  EXPECT_TRUE(runs[6].dense) << runs[6].id;  // real/stereo/pks@delta_deg=10
  const auto a = DenseArguments(s, runs[6], "data", "out/run");
  EXPECT_EQ(a[0], "dense");
  EXPECT_NE(std::find(a.begin(), a.end(), "out/run/dense.json"), a.end());
  const Suite all = ParseSuite("dense: true\n" + std::string(kSuite), "dir/suite.yaml");
  EXPECT_TRUE(ExpandSuite(all)[0].dense);
  ExpectError("dense: maybe\n" + std::string(kSuite), 1, "dense");
}

TEST(Suite, ExpandsTheMatrixInOrderWithDistinctSeeds) {
  const Suite s = ParseSuite(kSuite, "dir/suite.yaml");
  const auto runs = ExpandSuite(s);
  // real: 2 sensors x (2 selectors + 2 sweep points) x 3 runs; only_stereo: 1 x 4 x 3.
  ASSERT_EQ(runs.size(), 24u + 12u);
  EXPECT_EQ(runs[0].id, "real/stereo/orbslam3/seed10");
  EXPECT_EQ(runs[2].id, "real/stereo/orbslam3/seed12");
  EXPECT_EQ(runs[3].config, "pks");
  EXPECT_EQ(runs[3].params.at("tau"), 0.5);
  EXPECT_EQ(runs[3].params.at("min_frames"), 2.0);
  EXPECT_EQ(runs[6].config, "pks@delta_deg=10");
  EXPECT_EQ(runs[6].params.at("delta_deg"), 10.0);
  EXPECT_EQ(runs[6].params.at("tau"), 0.5);  // a sweep inherits its selector's params
  EXPECT_EQ(runs[9].sweep_value, 20.0);
  EXPECT_EQ(runs[12].sensor, "mono");
  EXPECT_EQ(runs[24].id, "only_stereo/stereo/orbslam3/seed10");
  for (std::size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(runs[i].index, static_cast<int>(i));
}

TEST(Suite, SensorSelectionKeepsTheOrderAndRejectsUnknownSensors) {
  const auto runs = ExpandSuite(ParseSuite(kSuite, "dir/suite.yaml"));
  const auto mono = SelectSensors(runs, {"mono"});
  ASSERT_EQ(mono.size(), 12u);  // only `real` runs mono
  EXPECT_EQ(mono.front().id, runs[12].id);
  for (const auto& r : mono) EXPECT_EQ(r.sensor, "mono");
  EXPECT_EQ(SelectSensors(runs, {}).size(), runs.size());
  EXPECT_THROW(SelectSensors(runs, {"rgbd"}), OptionError);
}

TEST(Suite, SweepsCanBeLimitedToDatasets) {
  const Suite s = ParseSuite(R"(sensors: [stereo]
runs: 1
selectors: [orbslam3, pks]
sweeps: [{selector: pks, param: delta, values: [10, 40], datasets: [b]}]
datasets: [{name: a, path: x}, {name: b, path: y}]
)",
                             "s.yaml");
  const auto runs = ExpandSuite(s);
  ASSERT_EQ(runs.size(), 2u + 4u);
  EXPECT_EQ(runs[1].id, "a/stereo/pks/seed1");
  EXPECT_EQ(runs[5].id, "b/stereo/pks@delta=40/seed1");
  ExpectError(
      "sensors: [stereo]\nselectors: [a]\nsweeps: [{selector: a, param: p, values: [1], "
      "datasets: [zz]}]\ndatasets: [{name: x, path: p}]\n",
      3, "sweep dataset 'zz'");
}

TEST(Suite, SimSeedPerRunGivesEachRunItsOwnRendering) {
  const Suite s = ParseSuite(R"(sensors: [stereo]
runs: 2
selectors: [orbslam3]
datasets:
  - {name: a, sim: {motion: easy, duration: 5, seed: 7, seed_per_run: true}}
  - {name: b, sim: {motion: easy, duration: 5, seed: 7}}
)",
                             "s.yaml");
  const auto runs = ExpandSuite(s);
  ASSERT_EQ(runs.size(), 4u);
  EXPECT_EQ(runs[0].sim->seed, 7u);
  EXPECT_EQ(runs[1].sim->seed, 8u);
  EXPECT_EQ(runs[2].sim->seed, 7u);
  EXPECT_EQ(runs[3].sim->seed, 7u);
}

TEST(Suite, ErrorsNameFileAndLine) {
  ExpectError("runs: 2\nselectors: [a]\nbogus: 1\n", 3, "unknown key 'bogus'");
  ExpectError("runs: zero\n", 1, "'runs' must be an integer");
  ExpectError("runs: 0\n", 1, "'runs' must be >= 1");
  ExpectError("sensors: [stereo]\nselectors: [a]\ndatasets:\n  - {name: x}\n", 4, "needs 'path'");
  ExpectError("sensors: [stereo]\nselectors: [a]\ndatasets:\n  - {name: x, path: p, sim: {}}\n", 4,
              "not both");
  ExpectError("sensors: [stereo]\nselectors: [a, a]\ndatasets: [{name: x, path: p}]\n", 2,
              "repeats");
  ExpectError(
      "sensors: [stereo]\nselectors: [a]\nsweeps: [{selector: b, param: p, values: [1]}]\n"
      "datasets: [{name: x, path: p}]\n",
      3, "not one of the suite's selectors");
  ExpectError("selectors: [a]\ndatasets: [{name: x, path: p}]\n", 1, "has no sensors");
  ExpectError("a: [1, 2\n", 2, "YAML syntax");
  ExpectError(
      "sensors: [stereo]\nselectors: [a]\ndatasets:\n  - {name: x, sim: {motion: easy, "
      "args: [--seed, 3]}}\n",
      4, "must not contain --seed");
  ExpectError("", 0, "empty suite");
}

TEST(Suite, ExpandsEnvironmentVariables) {
  setenv("PKSLAM_BENCH_TEST_ROOT", "/data/euroc", 1);
  unsetenv("PKSLAM_BENCH_TEST_UNSET");
  EXPECT_EQ(ExpandEnvironment("${PKSLAM_BENCH_TEST_ROOT}/MH_01", "f", 1), "/data/euroc/MH_01");
  EXPECT_EQ(ExpandEnvironment("${PKSLAM_BENCH_TEST_UNSET:-/x}/y", "f", 1), "/x/y");
  EXPECT_THROW(ExpandEnvironment("${PKSLAM_BENCH_TEST_UNSET}/y", "f", 1), InputError);
  EXPECT_THROW(ExpandEnvironment("${OOPS", "f", 1), InputError);
  ExpectError(
      "sensors: [stereo]\nselectors: [a]\ndatasets:\n  - name: x\n    path: "
      "${PKSLAM_BENCH_TEST_UNSET}/MH\n",
      5, "PKSLAM_BENCH_TEST_UNSET is not set");
}

TEST(Matrix, FormatsNumbersShortestRoundTrip) {
  EXPECT_EQ(FormatNumber(20.0), "20");
  EXPECT_EQ(FormatNumber(0.35), "0.35");
  EXPECT_EQ(FormatParams({{"b", 1.5}, {"a", 2}}), "a=2;b=1.5");
}

// Peers are extra configurations: one per dataset x sensor x run, with their command.
TEST(Suite, PeersExpandIntoTheMatrix) {
  const std::string text = R"(runs: 2
sensors: [stereo-inertial]
selectors: [orbslam3]
peers:
  - {label: orbslam3-peer, command: [bash, "{suite_dir}/run_peer", "{dataset}", "{sensor}", "{out}"]}
datasets:
  - {name: a, path: /data/a}
)";
  const Suite s = ParseSuite(text, "dir/suite.yaml");
  ASSERT_EQ(s.peers.size(), 1u);
  EXPECT_EQ(s.peers[0].command.size(), 5u);
  const auto runs = ExpandSuite(s);
  ASSERT_EQ(runs.size(), 4u);  // (orbslam3 + peer) x 2 runs
  EXPECT_TRUE(runs[0].peer_command.empty());
  EXPECT_EQ(runs[2].config, "orbslam3-peer");
  EXPECT_EQ(runs[2].selector, "peer");
  EXPECT_EQ(runs[2].peer_command, s.peers[0].command);
  EXPECT_EQ(runs[3].id, "a/stereo-inertial/orbslam3-peer/seed2");
}

// A study in passes: its peers alone, then pkslam's configurations (`pkslam bench --config`).
TEST(Suite, ConfigSelectionByLabelOrGroup) {
  const std::string text = R"(runs: 2
sensors: [stereo-inertial]
selectors: [orbslam3, pks]
peers:
  - {label: orbslam3-peer, command: [x]}
  - {label: pks-authors, command: [y]}
datasets:
  - {name: a, path: /data/a}
)";
  const auto runs = ExpandSuite(ParseSuite(text, "suite.yaml"));
  ASSERT_EQ(runs.size(), 8u);
  const auto peers = SelectConfigs(runs, {"peers"});
  ASSERT_EQ(peers.size(), 4u);
  for (const auto& r : peers) EXPECT_FALSE(r.peer_command.empty()) << r.id;
  const auto mine = SelectConfigs(runs, {"pkslam"});
  ASSERT_EQ(mine.size(), 4u);
  for (const auto& r : mine) EXPECT_TRUE(r.peer_command.empty()) << r.id;
  const auto two = SelectConfigs(runs, {"pks-authors", "orbslam3"});
  ASSERT_EQ(two.size(), 4u);
  EXPECT_EQ(two[0].config, "orbslam3");  // the matrix's order, not the arguments'
  EXPECT_EQ(SelectConfigs(runs, {}).size(), runs.size());
  EXPECT_THROW(SelectConfigs(runs, {"vins"}), OptionError);
  // A configuration labelled like a group is selected by its label only.
  const auto own = ExpandSuite(
      ParseSuite("runs: 1\nsensors: [stereo]\nselectors: [{name: pks, label: peers}]\npeers:\n"
                 "  - {label: p, command: [x]}\ndatasets:\n  - {name: a, path: /data/a}\n",
                 "suite.yaml"));
  const auto labelled = SelectConfigs(own, {"peers"});
  ASSERT_EQ(labelled.size(), 1u);
  EXPECT_EQ(labelled[0].config, "peers");
}

// A peer's `sensors` limits it to those sensors; the suite's selectors still run every sensor.
TEST(Suite, PeerSensorsLimitItsRuns) {
  const Suite s = ParseSuite(R"(runs: 1
sensors: [stereo, rgbd]
selectors: [orbslam3]
peers:
  - {label: p, command: [x], sensors: [stereo]}
datasets:
  - {name: a, path: /data/a}
)",
                             "suite.yaml");
  const auto runs = ExpandSuite(s);
  ASSERT_EQ(runs.size(), 3u);  // stereo: orbslam3 + p; rgbd: orbslam3 only
  EXPECT_EQ(runs[1].id, "a/stereo/p/seed1");
  EXPECT_EQ(runs[2].id, "a/rgbd/orbslam3/seed1");
}

// A suite of peers only (another system's runs beside a pkslam suite's, in their own folder).
TEST(Suite, APeerWithoutSelectorsIsASuite) {
  const std::string head = R"(runs: 2
sensors: [stereo-inertial]
selectors: []
)";
  const Suite s = ParseSuite(head + R"(peers:
  - {label: p, command: [x]}
datasets:
  - {name: a, path: /data/a}
)",
                             "suite.yaml");
  const auto runs = ExpandSuite(s);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[1].id, "a/stereo-inertial/p/seed2");
  ExpectError(head + "datasets:\n  - {name: a, path: /data/a}\n", 1, "no selectors or peers");
}

// A simulated dataset's own settings.yaml lives in its cache folder, known only at run time:
// "{dataset}" in `settings` is left for the executor to fill in.
TEST(Suite, SettingsInsideTheDatasetFolder) {
  const Suite s = ParseSuite(R"(runs: 1
sensors: [mono]
selectors: [orbslam3]
dense: true
datasets:
  - {name: a, sim: {motion: easy, duration: 5}, settings: "{dataset}/settings.yaml"}
  - {name: b, path: /data/b, settings: conf/b.yaml}
)",
                             "dir/suite.yaml");
  EXPECT_EQ(*s.datasets[0].settings, fs::path("{dataset}/settings.yaml"));  // not resolved
  EXPECT_EQ(*s.datasets[1].settings, fs::absolute("dir/conf/b.yaml"));
  const auto runs = ExpandSuite(s);
  ASSERT_EQ(runs.size(), 2u);
  auto settings_of = [](const std::vector<std::string>& a) {
    const auto it = std::find(a.begin(), a.end(), "--settings");
    return it == a.end() || it + 1 == a.end() ? std::string() : *(it + 1);
  };
  EXPECT_EQ(settings_of(RunArguments(s, runs[0], "/cache/a-seed1-0abc", "out")),
            "/cache/a-seed1-0abc/settings.yaml");
  EXPECT_EQ(settings_of(DenseArguments(s, runs[0], "/cache/a-seed1-0abc", "out")),
            "/cache/a-seed1-0abc/settings.yaml");
  EXPECT_EQ(settings_of(RunArguments(s, runs[1], "/data/b", "out")),
            fs::absolute("dir/conf/b.yaml").string());
}

// A peer's program and the files beside the suite it names are checked before a bench starts.
TEST(Suite, APeerWhosePathsAreMissingStopsTheBenchAtOnce) {
  const fs::path dir = testing::MakeTempDir("peer_paths");
  const fs::path script = dir / "run_peer";
  std::ofstream(script) << "#!/bin/sh\n";
  fs::permissions(script, fs::perms::owner_all);
  const std::string head =
      "sensors: [stereo]\nselectors: [orbslam3]\ndatasets: [{name: a, path: /a}]\n";
  const auto suite = [&](const std::string& peers) {
    return ParseSuite(head + "peers:\n" + peers, dir / "suite.yaml");
  };
  const Suite good = suite(
      "  - {label: p, command: [bash, '{suite_dir}/run_peer', '{dataset}']}\n"
      "  - {label: q, command: ['{suite_dir}/run_peer']}\n");
  EXPECT_NO_THROW(CheckPeerCommands(good, {"p", "q"}));
  const Suite bad = suite(
      "  - {label: p, command: [bash, '{suite_dir}/run_peer']}\n"
      "  - {label: q, command: ['{suite_dir}/../studies/run_peer', '{dataset}']}\n"
      "  - {label: r, command: [bash, '{suite_dir}/missing_script']}\n"
      "  - {label: s, command: [no-such-program-pkslam]}\n");
  EXPECT_NO_THROW(CheckPeerCommands(bad, {"p"}));
  EXPECT_NO_THROW(CheckPeerCommands(bad, {})) << "peers with nothing to run are not checked";
  const auto expect = [&](const std::string& label, std::size_t line, const std::string& what) {
    try {
      CheckPeerCommands(bad, {label});
      FAIL() << "no error for peer " << label;
    } catch (const InputError& e) {
      EXPECT_EQ(e.line(), line) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("suite.yaml"), std::string::npos) << e.what();
    }
  };
  expect("q", 6, "studies/run_peer");
  expect("r", 7, "missing_script' does not exist");
  expect("s", 8, "cannot run 'no-such-program-pkslam'");
}

// The suites the repository ships read, and their peers' scripts are where they say.
TEST(Suite, EveryShippedSuiteReadsAndItsPeersCanStart) {
  setenv("EUROC_ROOT", "/euroc", 0);  // suites of recorded data name their folder by these
  setenv("PKSLAM_CALIBRATION_RENDERS", "/renders", 0);
  int suites = 0, peers = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(PKSLAM_SOURCE_DIR) / "bench/suites")) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    const Suite s = ReadSuite(entry.path());
    std::set<std::string> labels;
    for (const PeerSpec& p : s.peers) labels.insert(p.label);
    EXPECT_NO_THROW(CheckPeerCommands(s, labels));
    ++suites;
    peers += static_cast<int>(labels.size());
  }
  EXPECT_GT(suites, 10);
  EXPECT_GT(peers, 4);
}

TEST(Suite, BadPeersAreErrors) {
  const std::string head =
      "sensors: [stereo]\nselectors: [orbslam3]\ndatasets: [{name: a, path: /a}]\n";
  ExpectError(head + "peers:\n  - {label: x}\n", 5, "needs 'label' and 'command'");
  ExpectError(head + "peers:\n  - {label: orbslam3, command: [x]}\n", 5, "repeats");
  ExpectError(head + "peers:\n  - {label: 'a b', command: [x]}\n", 5, "without");
  ExpectError(head + "peers:\n  - {label: p, command: [x], extra: 1}\n", 5, "unknown key");
}

}  // namespace
}  // namespace pkslam::bench
