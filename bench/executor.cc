#include "bench/executor.h"

#include <fmt/chrono.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <ctime>
#include <fstream>
#include <iterator>
#include <sstream>
#include <thread>

#include "bench/import_finished.h"
#include "bench/peer_import.h"
#include "bench/process.h"
#include "bench/run_evaluation.h"
#include "core/util/error.h"
#include "io/json_file.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

std::uint64_t Fnv1a(const std::string& text) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char ch : text) {
    h ^= ch;
    h *= 1099511628211ull;
  }
  return h;
}

// The last non-empty line of a log (the one-line error of a failed pkslam command).
std::string LastLine(const fs::path& log) {
  std::ifstream in(log);
  std::string line;
  std::string last;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  const std::size_t cr = last.rfind('\r');
  return cr == std::string::npos ? last : last.substr(cr + 1);
}

void WriteResult(const fs::path& run_dir, const RunResult& r) {
  WriteResultsCsv(run_dir / "result.csv", {r});
}

// The "points" field of `pkslam dense --json` (plain JSON, read as YAML flow style).
double ReadDensePoints(const fs::path& file) {
  if (!fs::exists(file)) throw InputError(file, "missing (pkslam dense wrote no statistics)");
  const YAML::Node root = ReadJsonFile(file);
  if (!root["points"]) throw InputError(file, "no 'points' field");
  try {
    return root["points"].as<double>();
  } catch (const YAML::Exception& e) {
    throw InputError(file, e.mark.line + 1, "not valid JSON: " + e.msg);
  }
}

bool LacksDenseCloud(const RunSpec& run, const RunResult& r) {
  return run.dense && r.ok && !std::isfinite(r.dense_points);
}

// Builds the dense cloud of a finished run (RUN/dense.ply, dense.json, dense.log) and records
// its point count; a failure marks the run failed. Returns false when cancelled.
bool AddDenseCloud(const Suite& suite, const RunSpec& run, const HarnessOptions& options,
                   const fs::path& dataset, const fs::path& run_dir, RunResult* result,
                   const std::atomic<bool>* cancel) {
  std::vector<std::string> argv = {options.pkslam.string()};
  const auto args = DenseArguments(suite, run, dataset, run_dir);
  argv.insert(argv.end(), args.begin(), args.end());
  const fs::path log = run_dir / "dense.log";
  { std::ofstream(log) << "# " << ShellCommand(argv) << '\n'; }
  const ProcessResult p = RunProcess(argv, log, suite.timeout_s, cancel);
  if (cancel != nullptr && cancel->load()) return false;
  if (!p.ok()) {
    result->ok = false;
    result->error = fmt::format("pkslam dense {}: {}", p.Describe(), LastLine(log));
    return true;
  }
  try {
    result->dense_points = ReadDensePoints(run_dir / "dense.json");
  } catch (const Error& e) {
    result->ok = false;
    result->error = std::string("dense: ") + e.what();
  }
  return true;
}

}  // namespace

std::optional<fs::path> SettingsFile(const DatasetSpec& d, const fs::path& dataset) {
  if (!d.settings) return std::nullopt;
  std::string text = d.settings->string();
  const std::string key = kDatasetPlaceholder;
  for (std::size_t at = text.find(key); at != std::string::npos;
       at = text.find(key, at + dataset.string().size())) {
    text.replace(at, key.size(), dataset.string());
  }
  return fs::path(text);
}

void HarnessOptions::Check() const {
  PKSLAM_CHECK_OPTION(jobs >= 1, "--jobs", "{} < 1", jobs);
  PKSLAM_CHECK_OPTION(!out.empty(), "--out", "empty");
  PKSLAM_CHECK_OPTION(!cache.empty(), "--cache", "empty");
  if (!fs::exists(pkslam)) throw OptionError("pkslam executable not found: " + pkslam.string());
  if (!simulator.empty() && !fs::exists(simulator)) {
    throw OptionError("--simulator: pkslam executable not found: " + simulator.string());
  }
}

fs::path RunDir(const fs::path& out, const RunSpec& run) { return out / "runs" / run.id; }

std::vector<std::string> SimulateArguments(const SimRecipe& r, const fs::path& out_dir) {
  std::vector<std::string> a = {
      "simulate", "--out", out_dir.string(), "--seed", std::to_string(r.seed), "--quiet"};
  if (!r.trajectory.empty()) {
    a.insert(a.end(), {"--trajectory", r.trajectory.string()});
  } else {
    a.insert(a.end(), {"--motion", r.motion});
  }
  if (r.start_s > 0) a.insert(a.end(), {"--start", FormatNumber(r.start_s)});
  if (r.duration_s > 0) a.insert(a.end(), {"--duration", FormatNumber(r.duration_s)});
  if (!r.scene.empty()) a.insert(a.end(), {"--scene", r.scene});
  if (!r.quality.empty()) a.insert(a.end(), {"--quality", r.quality});
  a.insert(a.end(), r.extra_args.begin(), r.extra_args.end());
  return a;
}

fs::path SimCacheDir(const HarnessOptions& options, const std::string& dataset,
                     const SimRecipe& recipe) {
  std::vector<std::string> args = SimulateArguments(recipe, "");
  std::string key = options.simulator_id;
  for (const auto& a : args) key += '\x1f' + a;
  return options.cache / fmt::format("{}-seed{}-{:08x}", dataset, recipe.seed,
                                     static_cast<std::uint32_t>(Fnv1a(key) & 0xffffffffu));
}

std::string ExecutableId(const fs::path& executable) {
  std::ifstream in(executable, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot read the executable", executable.string()));
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return fmt::format("{:016x}", Fnv1a(bytes));
}

fs::path EnsureSimulated(const HarnessOptions& options, const std::string& dataset,
                         const SimRecipe& recipe, const std::atomic<bool>* cancel) {
  const fs::path dir = SimCacheDir(options, dataset, recipe);
  const fs::path done = dir / ".complete";
  if (fs::exists(done)) return dir;
  FileLock lock(dir.string() + ".lock");
  if (fs::exists(done)) return dir;  // another job rendered it while we waited
  const fs::path tmp = dir.string() + ".partial";
  const fs::path log = dir.string() + ".log";
  fs::remove_all(tmp);
  fs::remove(log);
  std::vector<std::string> argv = {options.Simulator().string()};
  const auto args = SimulateArguments(recipe, tmp);
  argv.insert(argv.end(), args.begin(), args.end());
  { std::ofstream(log) << "# " << ShellCommand(argv) << '\n'; }
  const ProcessResult p = RunProcess(argv, log, 24.0 * 3600.0, cancel);
  if (!p.ok()) {
    throw Error(fmt::format("simulating {} failed ({}): {} (log {})", dataset, p.Describe(),
                            LastLine(log), log.string()));
  }
  fs::remove_all(dir);
  fs::rename(tmp, dir);
  std::ofstream(dir / "recipe.txt") << ShellCommand(argv) << '\n';
  std::ofstream(done) << fmt::format("{:.1f} s\n", p.wall_s);
  return dir;
}

fs::path PrepareDataset(const Suite& suite, const RunSpec& run, const HarnessOptions& options,
                        const std::atomic<bool>* cancel) {
  const DatasetSpec& d = DatasetOf(suite, run);
  if (run.sim) return EnsureSimulated(options, d.name, *run.sim, cancel);
  if (!fs::is_directory(*d.path)) {
    throw InputError(suite.file,
                     "dataset '" + d.name + "': " + d.path->string() + " is not a directory");
  }
  return *d.path;
}

std::vector<std::string> RunArguments(const Suite& suite, const RunSpec& run,
                                      const fs::path& dataset, const fs::path& run_dir) {
  const DatasetSpec& d = DatasetOf(suite, run);
  std::vector<std::string> a = {
      "run",      "--dataset",  dataset.string(), "--out",  run_dir.string(),         "--sensor",
      run.sensor, "--selector", run.selector,     "--seed", std::to_string(run.seed), "--quiet"};
  for (const auto& [k, v] : run.params) a.insert(a.end(), {"--param", k + "=" + FormatNumber(v)});
  if (const auto settings = SettingsFile(d, dataset)) {
    a.insert(a.end(), {"--settings", settings->string()});
  }
  if (d.max_frames > 0) a.insert(a.end(), {"--max-frames", std::to_string(d.max_frames)});
  if (suite.deterministic) a.push_back("--deterministic");
  if (suite.trace) a.push_back("--trace");
  a.insert(a.end(), run.run_args.begin(), run.run_args.end());
  return a;
}

std::vector<std::string> DenseArguments(const Suite& suite, const RunSpec& run,
                                        const fs::path& dataset, const fs::path& run_dir) {
  const DatasetSpec& d = DatasetOf(suite, run);
  std::vector<std::string> a = {"dense",
                                "--run",
                                run_dir.string(),
                                "--dataset",
                                dataset.string(),
                                "--out",
                                (run_dir / "dense.ply").string(),
                                "--json",
                                (run_dir / "dense.json").string(),
                                "--quiet"};
  if (const auto settings = SettingsFile(d, dataset)) {
    a.insert(a.end(), {"--settings", settings->string()});
  }
  return a;
}

std::optional<RunResult> ReadFinished(const fs::path& run_dir) {
  const fs::path file = run_dir / "result.csv";
  if (!fs::exists(file)) return std::nullopt;
  try {
    const auto rows = ReadResultsCsv(file);
    if (rows.size() == 1) return rows.front();
  } catch (const InputError&) {
  }
  return std::nullopt;  // unreadable: run again
}

namespace {

// A run with --prune-cache keeps a copy of its ground truth (its rendering is deleted), so it
// can be evaluated again.
std::optional<fs::path> KeptGroundTruth(const fs::path& run_dir) {
  for (const char* name : {"ground_truth.csv", "ground_truth.txt"}) {
    if (fs::exists(run_dir / name)) return run_dir / name;
  }
  return std::nullopt;
}

fs::path KeepGroundTruth(const fs::path& run_dir, const fs::path& dataset,
                         const std::optional<fs::path>& ground_truth) {
  const fs::path source = ground_truth ? *ground_truth : FindGroundTruth(dataset);
  const fs::path copy =
      run_dir / (source.extension() == ".csv" ? "ground_truth.csv" : "ground_truth.txt");
  std::error_code ec;
  fs::copy_file(source, copy, fs::copy_options::overwrite_existing, ec);
  if (ec)
    throw Error(
        fmt::format("cannot copy {} to {}: {}", source.string(), copy.string(), ec.message()));
  return copy;
}

// What made a run: this harness's pkslam, the machine, and for a peer the first line of the
// peer_build.txt its script wrote.
RunProvenance ProvenanceOf(const HarnessOptions& options, const fs::path& run_dir, bool peer) {
  RunProvenance p;
  p.pkslam_commit = options.pkslam_commit;
  p.executable = options.executable_id;
  p.cores = static_cast<int>(std::thread::hardware_concurrency());
  p.jobs = options.jobs;
  p.finished_utc = fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", fmt::gmtime(std::time(nullptr)));
  if (peer) {
    std::ifstream in(run_dir / "peer_build.txt");
    std::string line;
    if (in && std::getline(in, line)) p.peer_build = line;
  }
  return p;
}

}  // namespace

std::optional<RunResult> ReevaluateRun(const Suite& suite, const RunSpec& run,
                                       const HarnessOptions& options) {
  const fs::path run_dir = RunDir(options.out, run);
  const auto done = ReadFinished(run_dir);
  if (!done || !done->ok) return std::nullopt;
  if (IsImported(run_dir)) return done;  // no trajectory here: the recorded numbers stand
  RunResult result = ResultSkeleton(run, suite);
  result.dense_points = done->dense_points;
  result.provenance = done->provenance;  // what ran it, not this harness
  try {
    if (const auto kept = KeptGroundTruth(run_dir)) {
      EvaluateRun({run_dir, run_dir, kept, suite.rpe_delta_m}, &result);
    } else {
      const fs::path dataset = PrepareDataset(suite, run, options);
      const DatasetSpec& d = DatasetOf(suite, run);
      EvaluateRun({run_dir, dataset, d.ground_truth, suite.rpe_delta_m}, &result);
    }
  } catch (const Error& e) {
    result.ok = false;
    result.error = std::string("evaluation: ") + e.what();
  }
  WriteResult(run_dir, result);
  return result;
}

bool NeedsExecution(const HarnessOptions& options, const RunSpec& run) {
  const auto r = ReadFinished(RunDir(options.out, run));
  return !r || (!r->ok && options.retry_failed) || LacksDenseCloud(run, *r);
}

std::optional<RunResult> ExecuteRun(const Suite& suite, const RunSpec& run,
                                    const HarnessOptions& options,
                                    const std::atomic<bool>* cancel) {
  const fs::path run_dir = RunDir(options.out, run);
  // A finished run of a suite that asks for dense clouds now: only the cloud is missing.
  if (const auto done = ReadFinished(run_dir); done && LacksDenseCloud(run, *done)) {
    RunResult result = *done;
    try {
      const fs::path dataset = PrepareDataset(suite, run, options, cancel);
      if (!AddDenseCloud(suite, run, options, dataset, run_dir, &result, cancel)) {
        return std::nullopt;
      }
    } catch (const Error& e) {
      if (cancel != nullptr && cancel->load()) return std::nullopt;
      result.ok = false;
      result.error = std::string("dense: ") + e.what();
    }
    WriteResult(run_dir, result);
    return result;
  }
  RunResult result = ResultSkeleton(run, suite);
  fs::remove_all(run_dir);
  fs::create_directories(run_dir);
  fs::path dataset;
  try {
    dataset = PrepareDataset(suite, run, options, cancel);
  } catch (const Error& e) {
    if (cancel != nullptr && cancel->load()) return std::nullopt;
    result.error = e.what();
    WriteResult(run_dir, result);
    return result;
  }
  std::vector<std::string> argv = {options.pkslam.string()};
  const auto args = RunArguments(suite, run, dataset, run_dir);
  argv.insert(argv.end(), args.begin(), args.end());
  const bool peer = !run.peer_command.empty();
  if (peer) {
    argv = PeerArguments(run.peer_command, dataset, run.sensor, run_dir, run.seed,
                         fs::absolute(suite.file).parent_path());
  }
  const fs::path log = run_dir / (peer ? "peer.log" : "pkslam.log");
  std::ofstream(run_dir / "command.txt") << ShellCommand(argv) << '\n';
  ProcessResult p;
  try {
    p = RunProcess(argv, log, suite.timeout_s, cancel);
  } catch (const Error& e) {  // it could not be started: this run failed, not the bench
    result.error = e.what();
    WriteResult(run_dir, result);
    return result;
  }
  if (cancel != nullptr && cancel->load()) return std::nullopt;
  result.provenance = ProvenanceOf(options, run_dir, peer);
  if (!p.ok()) {
    result.error =
        fmt::format("{} {}: {}", peer ? run.config : "pkslam run", p.Describe(), LastLine(log));
    result.wall_s = p.wall_s;
    WriteResult(run_dir, result);
    return result;
  }
  try {
    if (peer) ImportPeerRun(run_dir, dataset, run.sensor);
    const DatasetSpec& d = DatasetOf(suite, run);
    std::optional<fs::path> ground_truth = d.ground_truth;
    if (options.prune_cache && run.sim)
      ground_truth = KeepGroundTruth(run_dir, dataset, ground_truth);
    EvaluateRun({run_dir, dataset, ground_truth, suite.rpe_delta_m}, &result);
  } catch (const Error& e) {
    result.ok = false;
    result.error = std::string("evaluation: ") + e.what();
  }
  if (result.ok && run.dense &&
      !AddDenseCloud(suite, run, options, dataset, run_dir, &result, cancel)) {
    return std::nullopt;
  }
  WriteResult(run_dir, result);
  return result;
}

}  // namespace pkslam::bench
