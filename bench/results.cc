#include "bench/results.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/util/error.h"
#include "core/util/output_file.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

std::string Num(double v) { return std::isfinite(v) ? fmt::format("{:.6g}", v) : ""; }

double ParseDouble(const std::string& s, const fs::path& file, std::size_t line,
                   const std::string& column) {
  if (s.empty() || s == "nan") return kNaN;
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != s.size()) throw InputError(file, line, column + ": '" + s + "' is not a number");
  return v;
}

long long ParseInt(const std::string& s, const fs::path& file, std::size_t line,
                   const std::string& column) {
  const double v = ParseDouble(s, file, line, column);
  if (!std::isfinite(v) || v != std::floor(v)) {
    throw InputError(file, line, column + ": '" + s + "' is not an integer");
  }
  return static_cast<long long>(v);
}

// An integer column that may be empty (0).
long long ParseOptionalInt(const std::string& s, const fs::path& file, std::size_t line,
                           const std::string& column) {
  return s.empty() ? 0 : ParseInt(s, file, line, column);
}

}  // namespace

std::string PrimaryAlignment(const std::string& sensor, const std::string& suite_choice) {
  if (suite_choice == "se3" || suite_choice == "sim3") return suite_choice;
  return sensor.rfind("mono", 0) == 0 ? "sim3" : "se3";
}

RunResult ResultSkeleton(const RunSpec& run, const Suite& suite) {
  RunResult r;
  r.index = run.index;
  r.run_id = run.id;
  r.dataset = run.dataset;
  r.sensor = run.sensor;
  r.config = run.config;
  r.selector = run.selector;
  r.params = FormatParams(run.params);
  r.sweep_param = run.sweep_param;
  r.sweep_value = run.sweep_param.empty() ? kNaN : run.sweep_value;
  r.seed = run.seed;
  r.baseline = suite.baseline;
  r.alignment = PrimaryAlignment(run.sensor, suite.alignment);
  return r;
}

std::vector<std::string> ResultColumns() {
  return {"index",
          "run_id",
          "dataset",
          "sensor",
          "config",
          "selector",
          "params",
          "sweep_param",
          "sweep_value",
          "seed",
          "baseline",
          "status",
          "error",
          "alignment",
          "ate_m",
          "ate_se3_rmse_m",
          "ate_sim3_rmse_m",
          "sim3_scale",
          "rpe_trans_rmse_m",
          "rpe_rot_rmse_deg",
          "coverage",
          "frames",
          "keyframes",
          "map_points",
          "lost_frames",
          "wall_s",
          "median_tracking_ms",
          "dense_points",
          "gyro_bias_err_pct",
          "accel_bias_err_pct",
          "realtime_factor",
          "p95_tracking_ms",
          "mapping_ms_per_kf",
          "cpu_s",
          "peak_memory_mib",
          "sequence_s",
          "mapping_cpu_s",
          "degraded",
          "keyframe_reasons",
          "suspect",
          "keyframes_created",
          "pkslam_commit",
          "executable",
          "peer_build",
          "cores",
          "jobs",
          "finished_utc"};
}

std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (char ch : text) {
    if (ch == '"') out += '"';
    out += (ch == '\n' || ch == '\r') ? ' ' : ch;
  }
  return out + "\"";
}

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char ch = line[i];
    if (quoted) {
      if (ch == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        out.back() += '"';
        ++i;
      } else if (ch == '"') {
        quoted = false;
      } else {
        out.back() += ch;
      }
    } else if (ch == '"') {
      quoted = true;
    } else if (ch == ',') {
      out.emplace_back();
    } else if (ch != '\r') {
      out.back() += ch;
    }
  }
  return out;
}

std::string ResultCsvHeader() {
  std::string out;
  for (const auto& c : ResultColumns()) {
    if (!out.empty()) out.push_back(',');
    out.append(c);
  }
  return out;
}

std::string ResultCsvRow(const RunResult& r) {
  const std::vector<std::string> f = {
      std::to_string(r.index),
      CsvField(r.run_id),
      CsvField(r.dataset),
      CsvField(r.sensor),
      CsvField(r.config),
      CsvField(r.selector),
      CsvField(r.params),
      CsvField(r.sweep_param),
      Num(r.sweep_value),
      std::to_string(r.seed),
      CsvField(r.baseline),
      r.ok ? "ok" : "failed",
      CsvField(r.error),
      r.alignment,
      Num(r.ate_m),
      Num(r.ate_se3_m),
      Num(r.ate_sim3_m),
      Num(r.scale),
      Num(r.rpe_trans_m),
      Num(r.rpe_rot_deg),
      Num(r.coverage),
      std::to_string(r.frames),
      std::to_string(r.keyframes),
      std::to_string(r.map_points),
      std::to_string(r.lost_frames),
      Num(r.wall_s),
      Num(r.median_tracking_ms),
      Num(r.dense_points),
      Num(r.gyro_bias_err_pct),
      Num(r.accel_bias_err_pct),
      Num(r.realtime_factor),
      Num(r.p95_tracking_ms),
      Num(r.mapping_ms_per_kf),
      Num(r.cpu_s),
      Num(r.peak_memory_mib),
      Num(r.sequence_s),
      Num(r.mapping_cpu_s),
      Num(r.degraded),
      CsvField(r.keyframe_reasons),
      Num(r.suspect),
      Num(r.keyframes_created),
      CsvField(r.provenance.pkslam_commit),
      CsvField(r.provenance.executable),
      CsvField(r.provenance.peer_build),
      r.provenance.cores > 0 ? std::to_string(r.provenance.cores) : "",
      r.provenance.jobs > 0 ? std::to_string(r.provenance.jobs) : "",
      CsvField(r.provenance.finished_utc)};
  std::string out;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (i > 0) out.push_back(',');
    out.append(f[i]);
  }
  return out;
}

void WriteResultsCsv(const fs::path& file, const std::vector<RunResult>& results) {
  if (file.has_parent_path()) fs::create_directories(file.parent_path());
  OutputFile output(file);
  output.stream() << ResultCsvHeader() << '\n';
  for (const auto& r : results) output.stream() << ResultCsvRow(r) << '\n';
  output.Commit();
}

std::vector<RunResult> ReadResultsCsv(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file, "cannot read");
  std::string line;
  if (!std::getline(in, line)) throw InputError(file, "empty file (expected a results.csv header)");
  const auto header = SplitCsvLine(line);
  const auto columns = ResultColumns();
  // Files from before the optional trailing columns: a prefix of the columns that holds at
  // least every required one (through median_tracking_ms).
  const std::size_t required =
      static_cast<std::size_t>(std::find(columns.begin(), columns.end(), "median_tracking_ms") -
                               columns.begin()) +
      1;
  if (header.size() < required || header.size() > columns.size() ||
      !std::equal(header.begin(), header.end(), columns.begin())) {
    throw InputError(file, 1,
                     "header does not match results.csv columns (" + ResultCsvHeader() + ")");
  }
  std::vector<RunResult> out;
  std::size_t n = 1;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty()) continue;
    const auto f = SplitCsvLine(line);
    if (f.size() != header.size()) {
      throw InputError(file, n, fmt::format("{} fields, expected {}", f.size(), header.size()));
    }
    RunResult r;
    std::size_t i = 0;
    auto next = [&]() -> const std::string& { return f[i++]; };
    r.index = static_cast<int>(ParseInt(next(), file, n, "index"));
    r.run_id = next();
    r.dataset = next();
    r.sensor = next();
    r.config = next();
    r.selector = next();
    r.params = next();
    r.sweep_param = next();
    r.sweep_value = ParseDouble(next(), file, n, "sweep_value");
    r.seed = static_cast<std::uint64_t>(ParseInt(next(), file, n, "seed"));
    r.baseline = next();
    const std::string status = next();
    if (status != "ok" && status != "failed") {
      throw InputError(file, n, "status '" + status + "' is not ok|failed");
    }
    r.ok = status == "ok";
    r.error = next();
    r.alignment = next();
    r.ate_m = ParseDouble(next(), file, n, "ate_m");
    r.ate_se3_m = ParseDouble(next(), file, n, "ate_se3_rmse_m");
    r.ate_sim3_m = ParseDouble(next(), file, n, "ate_sim3_rmse_m");
    r.scale = ParseDouble(next(), file, n, "sim3_scale");
    r.rpe_trans_m = ParseDouble(next(), file, n, "rpe_trans_rmse_m");
    r.rpe_rot_deg = ParseDouble(next(), file, n, "rpe_rot_rmse_deg");
    r.coverage = ParseDouble(next(), file, n, "coverage");
    r.frames = static_cast<int>(ParseInt(next(), file, n, "frames"));
    r.keyframes = static_cast<int>(ParseInt(next(), file, n, "keyframes"));
    r.map_points = static_cast<int>(ParseInt(next(), file, n, "map_points"));
    r.lost_frames = static_cast<int>(ParseInt(next(), file, n, "lost_frames"));
    r.wall_s = ParseDouble(next(), file, n, "wall_s");
    r.median_tracking_ms = ParseDouble(next(), file, n, "median_tracking_ms");
    // In the order of ResultColumns(); a file holds a prefix of them.
    double* optional[] = {&r.dense_points,    &r.gyro_bias_err_pct, &r.accel_bias_err_pct,
                          &r.realtime_factor, &r.p95_tracking_ms,   &r.mapping_ms_per_kf,
                          &r.cpu_s,           &r.peak_memory_mib,   &r.sequence_s,
                          &r.mapping_cpu_s,   &r.degraded};
    // Then keyframe_reasons (text), suspect, keyframes_created and the six provenance columns,
    // added last.
    constexpr std::size_t kLater = 9;
    PKSLAM_CHECK(required + std::size(optional) + kLater == columns.size(), "optional columns");
    for (std::size_t k = 0; k < std::size(optional) && required + k < header.size(); ++k) {
      *optional[k] = ParseDouble(next(), file, n, header[required + k]);
    }
    const auto has = [&](std::size_t later) {  // later: index among the last kLater columns
      return header.size() > columns.size() - kLater + later;
    };
    if (has(0)) r.keyframe_reasons = next();
    if (has(1)) r.suspect = ParseDouble(next(), file, n, "suspect");
    if (has(2)) r.keyframes_created = ParseDouble(next(), file, n, "keyframes_created");
    if (has(3)) r.provenance.pkslam_commit = next();
    if (has(4)) r.provenance.executable = next();
    if (has(5)) r.provenance.peer_build = next();
    if (has(6)) r.provenance.cores = static_cast<int>(ParseOptionalInt(next(), file, n, "cores"));
    if (has(7)) r.provenance.jobs = static_cast<int>(ParseOptionalInt(next(), file, n, "jobs"));
    if (has(8)) r.provenance.finished_utc = next();
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace pkslam::bench
