// pkslam bench: benchmark suites (datasets x sensors x selectors x sweeps x runs) with
// reports, resumable runs and scale-out job lists. See bench/ and README.md.
#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "bench/bench.h"
#include "bench/process.h"
#include "bench/report.h"
#include "core/util/build_info.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/output_guard.h"

namespace pkslam::apps {
namespace {

namespace fs = std::filesystem;

// Set by SIGINT/SIGTERM: running children are stopped, unfinished runs stay pending.
std::atomic<bool> bench_interrupted{false};

void OnBenchSignal(int signal) {
  bench_interrupted.store(true);
  std::signal(signal, SIG_DFL);
}

struct BenchArgs {
  std::string suite;
  std::string out;
  std::string cache;
  std::string emit_jobs;
  std::vector<std::string> collect;
  std::vector<std::string> run_ids;
  std::vector<std::string> sensors;
  std::vector<std::string> configs;
  std::string pkslam;
  std::string simulator;
  std::vector<std::string> resume_from;
  std::string python = "/usr/bin/python3";
  int jobs = 1;
  bool retry_failed = false;
  bool reevaluate = false;
  bool prune_cache = false;
  bool no_plots = false;
  bool list = false;
  bool quiet = false;
};

fs::path SelfExecutable() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw Error("cannot find the pkslam executable (/proc/self/exe); pass --pkslam");
  return exe;
}

// The commit `pkslam` was built from: this build's own, or what its --version says.
std::string CommitOf(const fs::path& pkslam) {
  std::error_code ec;
  if (fs::equivalent(pkslam, SelfExecutable(), ec)) return BuildCommit();
  const fs::path log = fs::temp_directory_path() / fmt::format("pkslam-version-{}.txt", getpid());
  fs::remove(log, ec);
  std::string commit = "unknown";
  if (bench::RunProcess({pkslam.string(), "--version"}, log, 30).ok()) {
    std::ifstream in(log);
    std::string line;
    std::getline(in, line);
    const auto at = line.find("(commit ");
    if (at != std::string::npos) {
      const auto start = at + 8;
      commit = line.substr(start, line.find_first_of(",)", start) - start);
    }
  }
  fs::remove(log, ec);
  return commit;
}

void PrintReport(const std::vector<bench::RunResult>& results, const bench::ReportFiles& files,
                 const fs::path& out) {
  for (const auto& t : bench::HeadlineTables(bench::Summarize(results))) {
    std::cout << t.title << "\n" << bench::MarkdownTable(t) << "\n";
  }
  std::cout << fmt::format(
      "report: {}/report.html ({} plots), {}/report.md, {}/results.csv, "
      "{}/summary.csv\n",
      out.string(), files.pngs.size(), out.string(), out.string(), out.string());
  if (!files.plot_error.empty()) std::cout << "plots unavailable: " << files.plot_error << "\n";
}

void Run(const BenchArgs& a) {
  bench::ReportOptions report;
  report.python = a.python;
  report.plots = !a.no_plots;
  if (!a.collect.empty()) {
    if (!a.suite.empty()) throw OptionError("--collect takes no SUITE");
    std::vector<fs::path> dirs(a.collect.begin(), a.collect.end());
    if (a.out.empty() && fs::is_regular_file(dirs.front())) {
      throw OptionError("--out DIR is required when the first --collect is a results.csv");
    }
    report.out = a.out.empty() ? dirs.front() : fs::path(a.out);
    for (const auto& d : dirs) report.run_roots.push_back(d / "runs");
    report.title = bench::ReadBenchTitle(dirs.front(), "pkslam bench");
    const auto results = bench::CollectResults(dirs);
    if (results.empty()) throw InputError(dirs.front(), "no finished runs to collect");
    std::cout << fmt::format("collected {} runs from {} source(s)\n", results.size(), dirs.size());
    PrintReport(results, bench::WriteReport(results, report), report.out);
    return;
  }
  if (a.suite.empty()) throw OptionError("a SUITE file is required (or --collect DIR)");
  const bench::Suite suite = bench::ReadSuite(a.suite);
  const auto all = bench::ExpandSuite(suite);
  const auto runs = bench::SelectRuns(
      bench::SelectConfigs(bench::SelectSensors(all, a.sensors), a.configs), a.run_ids);
  if (a.list) {
    for (const auto& r : runs) std::cout << r.id << '\n';
    return;
  }
  bench::HarnessOptions h;
  h.pkslam = a.pkslam.empty() ? SelfExecutable() : fs::path(a.pkslam);
  h.out = !a.emit_jobs.empty() ? a.emit_jobs : a.out;
  if (h.out.empty()) throw OptionError("--out DIR is required");
  if (!a.emit_jobs.empty() && !a.out.empty() && a.out != a.emit_jobs) {
    throw OptionError("--emit-jobs DIR is also the output folder: drop --out");
  }
  const char* env_cache = std::getenv("PKSLAM_SIM_CACHE");
  h.cache = !a.cache.empty()       ? fs::path(a.cache)
            : env_cache != nullptr ? fs::path(env_cache)
                                   : h.out / "sim_cache";
  h.jobs = a.jobs;
  h.quiet = a.quiet;
  h.retry_failed = a.retry_failed;
  h.reevaluate = a.reevaluate;
  h.prune_cache = a.prune_cache;
  h.simulator = a.simulator;
  h.resume_from.assign(a.resume_from.begin(), a.resume_from.end());
  h.Check();
  // Hashing reads the whole executable: once when the runs' pkslam also renders.
  h.executable_id = bench::ExecutableId(h.pkslam);
  h.simulator_id = h.simulator.empty() ? h.executable_id : bench::ExecutableId(h.simulator);
  h.pkslam_commit = CommitOf(h.pkslam);
  if (h.pkslam_commit.ends_with("-dirty")) {
    // Every row records this commit: a study's runs would name a tree that no commit holds.
    PKSLAM_LOG_WARN(
        "{}: built from a modified tree (commit {}): the results cannot be traced "
        "to a commit; build a clean checkout for a study",
        h.pkslam.string(), h.pkslam_commit);
  }
  if (!a.emit_jobs.empty()) {
    const auto e = bench::EmitJobs(suite, runs, h);
    std::cout << fmt::format(
        "emitted {} jobs ({} runs in the suite): {}\n  GNU parallel: parallel --jobs 2 < {}  "
        "(or sh {})\n  Slurm: sbatch {}\n  then: pkslam bench --collect {}\n",
        e.jobs, runs.size(), e.jobs_file.string(), e.jobs_file.string(), e.parallel_script.string(),
        e.slurm_script.string(), fs::absolute(h.out).string());
    return;
  }
  // The report replaces OUT/plots at the end: refuse a folder the bench did not make now, not
  // after hours of runs.
  CheckOwnedDirectory(h.out / "plots", "index.tsv");
  bench::WriteBenchInfo(h.out, suite);
  std::signal(SIGINT, OnBenchSignal);
  std::signal(SIGTERM, OnBenchSignal);
  bench::BenchCounts counts;
  const auto results = bench::RunSuite(suite, runs, h, &counts, &bench_interrupted);
  if (counts.cancelled) throw Error("interrupted: finished runs are kept; run again to resume");
  if (!a.run_ids.empty()) {
    // One job of an emitted list: its result.csv is the output; --collect reports.
    for (const auto& r : results) {
      if (!r.ok) throw Error(fmt::format("run {} failed: {}", r.run_id, r.error));
    }
    return;
  }
  std::cout << fmt::format("{} runs: {} executed, {} already finished, {} failed\n", counts.total,
                           counts.executed, counts.skipped, counts.failed);
  report.out = h.out;
  report.title = suite.name;
  PrintReport(results, bench::WriteReport(results, report), h.out);
  // A sweep with failed runs is not a success: scripts and CI must see it (the report and
  // results.csv are written first, so the finished runs are not lost).
  if (counts.failed > 0) {
    throw Error(fmt::format(
        "{} of {} runs failed (status and error per run in {}/results.csv; --retry-failed runs "
        "them again)",
        counts.failed, counts.total, h.out.string()));
  }
}

}  // namespace

void RegisterBenchCommand(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  auto* cmd = app.add_subcommand(
      "bench",
      "Benchmark suite: datasets x sensors x keyframe selectors x sweeps x runs -> results.csv, "
      "summary tables, report.md/report.html with plots; resumable; scale-out job lists");
  cmd->add_option("suite", args->suite, "Suite YAML (see bench/suites/)");
  cmd->add_option("--out", args->out, "Output folder (runs/, results.csv, report.html)");
  cmd->add_option("-j,--jobs", args->jobs, "Runs executed at once (child processes)")
      ->capture_default_str();
  cmd->add_option("--cache", args->cache,
                  "Simulator renderings cache (default: $PKSLAM_SIM_CACHE or OUT/sim_cache)");
  cmd->add_option("--emit-jobs", args->emit_jobs,
                  "Write DIR/jobs.txt (one command per pending run, for GNU parallel), "
                  "DIR/run_parallel.sh and DIR/slurm.sh instead of running");
  cmd->add_option("--collect", args->collect,
                  "Merge the finished runs of these folders into one report (in --out, default "
                  "the first folder); a results.csv among them adds its recorded rows (a later "
                  "source wins for a run id found twice)");
  cmd->add_option("--run-id", args->run_ids,
                  "Execute only these runs (ids as --list prints); no report is written: `pkslam "
                  "bench --collect OUT` makes it");
  cmd->add_option("--sensor", args->sensors,
                  "Only the runs of these sensors (a study split over sittings, one sensor "
                  "first; the report covers the runs selected)");
  cmd->add_option("--config", args->configs,
                  "Only the runs of these configurations: labels, or `peers` / `pkslam` for "
                  "every peer / every pkslam configuration (a study in passes: the peers alone "
                  "at --jobs 1, then pkslam's runs at --jobs 2)");
  cmd->add_flag("--retry-failed", args->retry_failed, "Run failed runs again");
  cmd->add_flag("--prune-cache", args->prune_cache,
                "Render each simulated dataset just before its runs and delete it after them "
                "(disk holds ~--jobs renderings; for suites with seed_per_run)");
  cmd->add_flag("--reevaluate", args->reevaluate,
                "Measure finished runs again against ground truth (no SLAM re-run)");
  cmd->add_flag("--list", args->list, "Print the run ids of the matrix and exit");
  cmd->add_flag("--no-plots", args->no_plots, "Tables only (no matplotlib)");
  cmd->add_option("--python", args->python, "Python with matplotlib and numpy for the plots")
      ->capture_default_str();
  cmd->add_option("--pkslam", args->pkslam, "pkslam executable for the runs (default: this one)");
  cmd->add_option("--simulator", args->simulator,
                  "pkslam executable that renders the simulated datasets and keys their cache "
                  "(default: --pkslam): a study run in passes by different builds replays the "
                  "same renderings");
  cmd->add_option("--resume-from", args->resume_from,
                  "results.csv of an earlier collection: its runs count as finished (a study "
                  "resumes where its recorded results end, without the old run folders)");
  cmd->add_flag("--quiet", args->quiet, "No progress bars");
  cmd->callback([args] { Run(*args); });
}

}  // namespace pkslam::apps
