#include "bench/bench.h"

#include <yaml-cpp/yaml.h>

#include <condition_variable>
#include <deque>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "bench/import_finished.h"
#include "bench/process.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/progress.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

// Runs work(i) for i in [0, n) on `jobs` threads. The calling thread owns `progress` and
// calls done(i) for each finished item (so the Progress object is only touched by it); the
// queue of finished items is guarded by `mutex`.
void ParallelFor(int n, int jobs, const std::atomic<bool>* cancel,
                 const std::function<void(int)>& work, const std::function<void(int)>& done) {
  std::mutex mutex;
  std::condition_variable cv;
  std::deque<int> finished;
  std::atomic<int> next{0};
  std::vector<std::thread> threads;
  std::exception_ptr failure;
  for (int t = 0; t < std::min(jobs, n); ++t) {
    threads.emplace_back([&] {
      for (;;) {
        const int i = next.fetch_add(1);
        if (i >= n || (cancel != nullptr && cancel->load())) break;
        try {
          work(i);
        } catch (...) {
          std::lock_guard<std::mutex> lock(mutex);
          if (!failure) failure = std::current_exception();
        }
        std::lock_guard<std::mutex> lock(mutex);
        finished.push_back(i);
        cv.notify_one();
      }
      std::lock_guard<std::mutex> lock(mutex);
      finished.push_back(-1);  // this thread is done
      cv.notify_one();
    });
  }
  int live = static_cast<int>(threads.size());
  while (live > 0) {
    std::unique_lock<std::mutex> lock(mutex);
    cv.wait(lock, [&] { return !finished.empty(); });
    const int i = finished.front();
    finished.pop_front();
    lock.unlock();
    if (i < 0) {
      --live;
    } else {
      done(i);
    }
  }
  for (auto& t : threads) t.join();
  if (failure) std::rethrow_exception(failure);
}

std::string SimKey(const HarnessOptions& options, const RunSpec& run) {
  return SimCacheDir(options, run.dataset, *run.sim).string();
}

// --resume-from: the recorded runs become finished runs of OUT before anything is scheduled.
void ImportRecorded(const HarnessOptions& options, const std::vector<RunSpec>& runs) {
  for (const auto& file : options.resume_from) {
    const ImportCounts i = ImportFinished(file, runs, options.out);
    PKSLAM_LOG_INFO("{}: {} finished runs imported, {} already here, {} not in this selection",
                    file.string(), i.imported, i.present, i.other);
  }
}

}  // namespace

std::vector<RunSpec> SelectRuns(const std::vector<RunSpec>& runs,
                                const std::vector<std::string>& only) {
  if (only.empty()) return runs;
  std::vector<RunSpec> out;
  for (const auto& id : only) {
    bool found = false;
    for (const auto& r : runs) {
      if (r.id == id) {
        out.push_back(r);
        found = true;
      }
    }
    if (!found) throw OptionError("--run-id '" + id + "' is not a run of the suite");
  }
  return out;
}

std::vector<RunResult> RunSuite(const Suite& suite, const std::vector<RunSpec>& runs,
                                const HarnessOptions& options, BenchCounts* counts,
                                const std::atomic<bool>* cancel) {
  options.Check();
  fs::create_directories(options.out);
  ImportRecorded(options, runs);
  BenchCounts c;
  c.total = static_cast<int>(runs.size());
  std::vector<const RunSpec*> pending;
  std::vector<const RunSpec*> finished;
  for (const auto& r : runs) {
    (NeedsExecution(options, r) ? pending : finished).push_back(&r);
  }
  if (options.reevaluate && !finished.empty()) {
    Progress progress("evaluate", finished.size(), options.quiet);
    ParallelFor(
        static_cast<int>(finished.size()), options.jobs, cancel,
        [&](int i) { ReevaluateRun(suite, *finished[i], options); }, [&](int) { progress.Add(); });
  }
  std::set<std::string> pending_peers;
  for (const RunSpec* r : pending) {
    if (!r->peer_command.empty()) pending_peers.insert(r->config);
  }
  CheckPeerCommands(suite, pending_peers);
  c.skipped = c.total - static_cast<int>(pending.size());
  if (c.skipped > 0) PKSLAM_LOG_INFO("{} of {} runs already finished: skipped", c.skipped, c.total);

  // With prune_cache the runs of one recipe run together (matrix order within), run 1 of every
  // dataset before run 2 of any (RenderingOrder), and each rendering is made by its first run
  // and deleted after its last.
  std::map<std::string, int> runs_per_render;
  if (options.prune_cache) {
    pending = RenderingOrder(std::move(pending), [&](const RunSpec& r) {
      return r.sim ? std::optional<std::string>(SimKey(options, r)) : std::nullopt;
    });
    for (const RunSpec* r : pending) {
      if (r->sim) ++runs_per_render[SimKey(options, *r)];
    }
  }

  // 1. Simulator recipes, each rendered once (a failure fails only the runs that need it).
  std::vector<const RunSpec*> recipes;
  std::set<std::string> seen;
  for (const RunSpec* r : pending) {
    if (!r->sim) continue;
    const std::string key = SimKey(options, *r);  // the recipe's cache folder
    if (seen.insert(key).second && !fs::exists(fs::path(key) / ".complete")) recipes.push_back(r);
  }
  std::map<std::string, std::string> sim_errors;
  std::mutex sim_errors_mutex;
  if (!recipes.empty() && !options.prune_cache) {
    Progress progress("simulate", recipes.size(), options.quiet);
    ParallelFor(
        static_cast<int>(recipes.size()), options.jobs, cancel,
        [&](int i) {
          const RunSpec& r = *recipes[i];
          try {
            EnsureSimulated(options, r.dataset, *r.sim, cancel);
          } catch (const Error& e) {
            std::lock_guard<std::mutex> lock(sim_errors_mutex);
            sim_errors[SimKey(options, r)] = e.what();
          }
        },
        [&](int) { progress.Add(); });
  }

  // 2. The runs.
  if (!pending.empty() && !(cancel != nullptr && cancel->load())) {
    Progress progress("bench", pending.size(), options.quiet);
    std::vector<std::optional<RunResult>> done(pending.size());
    ParallelFor(
        static_cast<int>(pending.size()), options.jobs, cancel,
        [&](int i) {
          const RunSpec& r = *pending[i];
          if (r.sim) {
            const auto it = sim_errors.find(SimKey(options, r));
            if (it != sim_errors.end()) {
              RunResult failed = ResultSkeleton(r, suite);
              failed.error = it->second;
              fs::create_directories(RunDir(options.out, r));
              WriteResultsCsv(RunDir(options.out, r) / "result.csv", {failed});
              done[i] = failed;
              return;
            }
          }
          done[i] = ExecuteRun(suite, r, options, cancel);
        },
        [&](int i) {
          progress.Add();
          if (options.prune_cache && pending[i]->sim) {
            const std::string key = SimKey(options, *pending[i]);
            if (--runs_per_render[key] == 0 && !(cancel != nullptr && cancel->load())) {
              std::error_code ec;
              fs::remove_all(key, ec);
              if (ec) PKSLAM_LOG_WARN("cannot delete rendering {}: {}", key, ec.message());
            }
          }
          if (!done[i]) return;
          ++c.executed;
          const RunResult& r = *done[i];
          progress.SetSuffix(r.ok ? fmt::format("{} ATE {:.4f} m", r.config, r.ate_m)
                                  : fmt::format("{} FAILED", r.config));
          if (!r.ok) PKSLAM_LOG_WARN("run {} failed: {}", r.run_id, r.error);
        });
  }
  c.cancelled = cancel != nullptr && cancel->load();

  std::vector<RunResult> results;
  for (const auto& r : runs) {
    if (auto f = ReadFinished(RunDir(options.out, r))) {
      if (!f->ok) ++c.failed;
      results.push_back(std::move(*f));
    }
  }
  if (counts != nullptr) *counts = c;
  return results;
}

void WriteBenchInfo(const fs::path& out, const Suite& suite) {
  fs::create_directories(out);
  YAML::Emitter e;
  e << YAML::BeginMap << YAML::Key << "title" << YAML::Value << suite.name << YAML::Key << "suite"
    << YAML::Value << fs::absolute(suite.file).string() << YAML::EndMap;
  std::ofstream(out / "bench.yaml") << e.c_str() << '\n';
}

std::string ReadBenchTitle(const fs::path& out, const std::string& fallback) {
  try {
    const YAML::Node n = YAML::LoadFile((out / "bench.yaml").string());
    if (n["title"]) return n["title"].as<std::string>();
  } catch (const YAML::Exception&) {
  }
  return fallback;
}

EmittedJobs EmitJobs(const Suite& suite, const std::vector<RunSpec>& runs,
                     const HarnessOptions& options) {
  options.Check();
  const fs::path out = fs::absolute(options.out);
  WriteBenchInfo(out, suite);
  ImportRecorded(options, runs);
  EmittedJobs e;
  e.jobs_file = out / "jobs.txt";
  e.parallel_script = out / "run_parallel.sh";
  e.slurm_script = out / "slurm.sh";
  {
    std::ofstream jobs(e.jobs_file, std::ios::trunc);
    for (const auto& r : runs) {
      if (!NeedsExecution(options, r)) continue;
      std::vector<std::string> argv = {
          fs::absolute(options.pkslam).string(), "--log-level", "warn",       "bench",
          fs::absolute(suite.file).string(),     "--out",       out.string(), "--cache",
          fs::absolute(options.cache).string(),  "--run-id",    r.id,         "--quiet"};
      if (options.retry_failed) argv.push_back("--retry-failed");
      if (!options.simulator.empty()) {
        argv.insert(argv.end(), {"--simulator", fs::absolute(options.simulator).string()});
      }
      jobs << ShellCommand(argv) << '\n';
      ++e.jobs;
    }
    if (!jobs) throw Error("cannot write " + e.jobs_file.string());
  }
  const std::string collect =
      ShellCommand({fs::absolute(options.pkslam).string(), "bench", "--collect", out.string()});
  {
    std::ofstream sh(e.parallel_script, std::ios::trunc);
    sh << "#!/bin/sh\n"
          "# Runs the benchmark's jobs with GNU parallel, then writes the report.\n"
          "#   JOBS=4 sh run_parallel.sh             4 jobs at a time on this machine\n"
          "#   SSHLOGINFILE=hosts sh run_parallel.sh  across machines (shared file system)\n"
          "set -e\n"
          "cd \"$(dirname \"$0\")\"\n"
          "if [ -n \"$SSHLOGINFILE\" ]; then remote=\"--sshloginfile $SSHLOGINFILE\"; fi\n"
          "parallel --will-cite --jobs \"${JOBS:-2}\" $remote --joblog parallel.joblog < jobs.txt "
          "|| true\n"
       << collect << "\n";
  }
  {
    std::ofstream sh(e.slurm_script, std::ios::trunc);
    sh << "#!/bin/bash\n"
          "# Slurm array job over jobs.txt (one run per task):  sbatch slurm.sh\n"
          "# then, when all tasks are done:  "
       << collect
       << "\n"
          "#SBATCH --job-name=pkslam-bench\n"
       << fmt::format("#SBATCH --array=1-{}\n", std::max(e.jobs, 1))
       << "#SBATCH --cpus-per-task=4\n"
          "#SBATCH --time=02:00:00\n"
       << fmt::format("#SBATCH --output={}/slurm-%A_%a.out\n", out.string())
       << fmt::format("cmd=$(sed -n \"${{SLURM_ARRAY_TASK_ID}}p\" {})\n",
                      ShellQuote(e.jobs_file.string()))
       << "eval \"$cmd\"\n";
  }
  fs::permissions(e.parallel_script, fs::perms::owner_exec | fs::perms::group_exec,
                  fs::perm_options::add);
  fs::permissions(e.slurm_script, fs::perms::owner_exec | fs::perms::group_exec,
                  fs::perm_options::add);
  return e;
}

}  // namespace pkslam::bench
