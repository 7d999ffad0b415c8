#include "bench/summary.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>

#include "bench/matrix.h"
#include "core/util/error.h"
#include "core/util/output_file.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

std::string Num(double v) { return std::isfinite(v) ? fmt::format("{:.6g}", v) : ""; }

double Median(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// "—" for a value not measured.
std::string Fixed(double v, int decimals) {
  return std::isfinite(v) ? fmt::format("{:.{}f}", v, decimals) : "—";
}

SpeedMedians MedianSpeed(const std::vector<const RunResult*>& runs) {
  std::vector<double> rt, track, p95, mapping, cpu, memory;
  for (const RunResult* r : runs) {
    if (!r->ok) continue;
    rt.push_back(r->realtime_factor);
    track.push_back(r->median_tracking_ms);
    p95.push_back(r->p95_tracking_ms);
    mapping.push_back(r->mapping_ms_per_kf);
    cpu.push_back(r->cpu_s);
    memory.push_back(r->peak_memory_mib);
  }
  return {Median(rt), Median(track), Median(p95), Median(mapping), Median(cpu), Median(memory)};
}

// Realtime factor of `g` over that of the peer configuration `peer` on the same dataset and
// sensor (NaN for the peers themselves and where either is missing).
double RealtimeRatio(const GroupSummary& g, const std::string& peer,
                     const std::vector<GroupSummary>& groups) {
  if (g.selector == "peer") return kNaN;
  for (const auto& p : groups) {
    if (p.config == peer && p.dataset == g.dataset && p.sensor == g.sensor &&
        p.speed.realtime_factor > 0) {
      return g.speed.realtime_factor / p.speed.realtime_factor;
    }
  }
  return kNaN;
}

std::string Percent(double p) {
  if (!std::isfinite(p)) return "";
  return fmt::format("{:+.1f}%", p);
}

}  // namespace

MeanStd ComputeMeanStd(const std::vector<double>& values) {
  MeanStd m;
  double sum = 0;
  for (double v : values) {
    if (std::isfinite(v)) {
      sum += v;
      ++m.n;
    }
  }
  if (m.n == 0) return m;
  m.mean = sum / m.n;
  double ss = 0;
  for (double v : values) {
    if (std::isfinite(v)) ss += (v - m.mean) * (v - m.mean);
  }
  m.std = m.n > 1 ? std::sqrt(ss / (m.n - 1)) : 0.0;
  return m;
}

namespace {

// Eq. 13 of the PKS paper over each sweep (dataset, sensor, selector, parameter) whose points
// have dense clouds. A sweep where every value gives the same density (or ATE) contributes 0
// for that term rather than dividing by zero.
void ScoreSweeps(std::vector<GroupSummary>* groups) {
  auto scored = [](const GroupSummary& g) {
    return !g.sweep_param.empty() && g.dense_points.n > 0 && std::isfinite(g.ate_m.mean);
  };
  for (auto& g : *groups) {
    if (!scored(g)) continue;
    double d_lo = g.dense_points.mean, d_hi = d_lo, a_lo = g.ate_m.mean, a_hi = a_lo;
    int points = 0;
    for (const auto& o : *groups) {
      if (!scored(o) || o.dataset != g.dataset || o.sensor != g.sensor ||
          o.selector != g.selector || o.sweep_param != g.sweep_param) {
        continue;
      }
      ++points;
      d_lo = std::min(d_lo, o.dense_points.mean);
      d_hi = std::max(d_hi, o.dense_points.mean);
      a_lo = std::min(a_lo, o.ate_m.mean);
      a_hi = std::max(a_hi, o.ate_m.mean);
    }
    if (points < 2) continue;
    auto normalised = [](double x, double lo, double hi) {
      return hi > lo ? (x - lo) / (hi - lo) : 0.0;
    };
    g.sweep_score =
        normalised(g.dense_points.mean, d_lo, d_hi) - normalised(g.ate_m.mean, a_lo, a_hi);
  }
}

}  // namespace

std::vector<GroupSummary> Summarize(const std::vector<RunResult>& results) {
  using Key = std::tuple<std::string, std::string, std::string>;
  std::map<Key, std::vector<const RunResult*>> by_group;
  for (const auto& r : results) by_group[{r.dataset, r.sensor, r.config}].push_back(&r);
  std::vector<GroupSummary> groups;
  for (const auto& [key, runs] : by_group) {
    GroupSummary g;
    const RunResult& first = *runs.front();
    g.order = first.index;
    g.dataset = first.dataset;
    g.sensor = first.sensor;
    g.config = first.config;
    g.selector = first.selector;
    g.sweep_param = first.sweep_param;
    g.sweep_value = first.sweep_value;
    g.baseline = first.baseline;
    g.alignment = first.alignment;
    g.runs = static_cast<int>(runs.size());
    std::vector<double> ate, se3, sim3, scale, rpe, kf, mp, lost, wall, track, coverage, dense, bg,
        ba;
    for (const RunResult* r : runs) {
      g.order = std::min(g.order, r->index);
      if (!r->ok) continue;
      ++g.ok;
      ate.push_back(r->ate_m);
      se3.push_back(r->ate_se3_m);
      sim3.push_back(r->ate_sim3_m);
      scale.push_back(r->scale);
      rpe.push_back(r->rpe_trans_m);
      kf.push_back(r->keyframes);
      mp.push_back(r->map_points);
      lost.push_back(r->lost_frames);
      wall.push_back(r->wall_s);
      track.push_back(r->median_tracking_ms);
      coverage.push_back(r->coverage);
      dense.push_back(r->dense_points);
      bg.push_back(r->gyro_bias_err_pct);
      ba.push_back(r->accel_bias_err_pct);
    }
    g.ate_m = ComputeMeanStd(ate);
    g.ate_se3_m = ComputeMeanStd(se3);
    g.ate_sim3_m = ComputeMeanStd(sim3);
    g.scale = ComputeMeanStd(scale);
    g.rpe_trans_m = ComputeMeanStd(rpe);
    g.keyframes = ComputeMeanStd(kf);
    g.map_points = ComputeMeanStd(mp);
    g.lost_frames = ComputeMeanStd(lost);
    g.wall_s = ComputeMeanStd(wall);
    g.median_tracking_ms = ComputeMeanStd(track);
    g.coverage = ComputeMeanStd(coverage);
    g.dense_points = ComputeMeanStd(dense);
    g.gyro_bias_err_pct = ComputeMeanStd(bg);
    g.accel_bias_err_pct = ComputeMeanStd(ba);
    g.ate_median_m = Median(ate);
    g.speed = MedianSpeed(runs);
    groups.push_back(std::move(g));
  }
  std::sort(groups.begin(), groups.end(),
            [](const GroupSummary& a, const GroupSummary& b) { return a.order < b.order; });
  for (auto& g : groups) {
    for (const auto& b : groups) {
      if (b.dataset == g.dataset && b.sensor == g.sensor && b.config == g.baseline &&
          std::isfinite(b.ate_m.mean) && b.ate_m.mean > 0 && std::isfinite(g.ate_m.mean)) {
        g.ate_change_pct = 100.0 * (g.ate_m.mean - b.ate_m.mean) / b.ate_m.mean;
      }
    }
  }
  ScoreSweeps(&groups);
  return groups;
}

void WriteSummaryCsv(const fs::path& file, const std::vector<GroupSummary>& groups) {
  OutputFile output(file);
  std::ostream& out = output.stream();
  out << "dataset,sensor,config,selector,sweep_param,sweep_value,runs,ok,alignment,"
         "ate_mean_m,ate_std_m,ate_median_m,ate_se3_mean_m,ate_sim3_mean_m,scale_mean,"
         "rpe_trans_mean_m,ate_change_pct,keyframes_mean,keyframes_std,map_points_mean,"
         "lost_frames_mean,coverage_mean,wall_mean_s,median_tracking_mean_ms,dense_points_mean,"
         "sweep_score,gyro_bias_err_mean_pct,accel_bias_err_mean_pct\n";
  for (const auto& g : groups) {
    out << fmt::format(
        "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
        CsvField(g.dataset), CsvField(g.sensor), CsvField(g.config), CsvField(g.selector),
        CsvField(g.sweep_param), Num(g.sweep_value), g.runs, g.ok, g.alignment, Num(g.ate_m.mean),
        Num(g.ate_m.std), Num(g.ate_median_m), Num(g.ate_se3_m.mean), Num(g.ate_sim3_m.mean),
        Num(g.scale.mean), Num(g.rpe_trans_m.mean), Num(g.ate_change_pct), Num(g.keyframes.mean),
        Num(g.keyframes.std), Num(g.map_points.mean), Num(g.lost_frames.mean), Num(g.coverage.mean),
        Num(g.wall_s.mean), Num(g.median_tracking_ms.mean), Num(g.dense_points.mean),
        Num(g.sweep_score), Num(g.gyro_bias_err_pct.mean), Num(g.accel_bias_err_pct.mean));
  }
  output.Commit();
}

std::string FormatMeanStd(const MeanStd& m, int decimals) {
  if (m.n == 0) return "—";
  if (m.n == 1) return fmt::format("{:.{}f} (1 run)", m.mean, decimals);
  if (m.std == 0.0) return fmt::format("{:.{}f} ({} identical runs)", m.mean, decimals, m.n);
  return fmt::format("{:.{}f} ± {:.{}f}", m.mean, decimals, m.std, decimals);
}

std::vector<Table> HeadlineTables(const std::vector<GroupSummary>& groups) {
  std::vector<std::string> sensors, configs, datasets;
  auto add = [](std::vector<std::string>& v, const std::string& x) {
    if (std::find(v.begin(), v.end(), x) == v.end()) v.push_back(x);
  };
  for (const auto& g : groups) {
    add(sensors, g.sensor);
    add(datasets, g.dataset);
    if (g.sweep_param.empty()) add(configs, g.config);
  }
  std::vector<Table> tables;
  for (const auto& sensor : sensors) {
    Table t;
    std::string alignment;
    std::map<std::string, std::vector<double>> changes;
    for (const auto& dataset : datasets) {
      std::vector<std::string> row = {dataset};
      bool any = false;
      for (const auto& config : configs) {
        std::string cell = "";
        for (const auto& g : groups) {
          if (g.sensor != sensor || g.dataset != dataset || g.config != config) continue;
          any = true;
          alignment = g.alignment;
          cell = FormatMeanStd(g.ate_m, 4);
          if (config != g.baseline && std::isfinite(g.ate_change_pct)) {
            cell += " (" + Percent(g.ate_change_pct) + ")";
            changes[config].push_back(g.ate_change_pct);
          }
          if (g.ok < g.runs) cell += fmt::format(" [{}/{} ok]", g.ok, g.runs);
          if (g.coverage.n > 0 && g.coverage.mean < kLowCoverage) {
            cell += fmt::format(" [cov {:.0f}%]", 100.0 * g.coverage.mean);
          }
        }
        row.push_back(cell);
      }
      if (any) t.rows.push_back(row);
    }
    if (t.rows.empty()) continue;
    t.title = fmt::format(
        "ATE RMSE [m] ({} alignment), {}: mean ± std over runs (ATE change against the "
        "baseline; negative = lower error)",
        alignment == "sim3" ? "Sim(3)" : "SE(3)", sensor);
    t.header = {"dataset"};
    t.header.insert(t.header.end(), configs.begin(), configs.end());
    if (!changes.empty()) {
      // The paper's summary lines: mean ATE over the sequences (and its change), the mean of
      // the per-sequence changes, and on how many sequences a configuration's ATE is lower.
      std::vector<std::string> mean_row = {"mean over sequences"};
      std::vector<std::string> avg_row = {"mean of per-sequence changes"};
      std::vector<std::string> wins_row = {"lower ATE than the baseline on"};
      std::map<std::string, double> mean_ate;
      for (const auto& config : configs) {
        std::vector<double> means;
        for (const auto& g : groups) {
          if (g.sensor == sensor && g.config == config) means.push_back(g.ate_m.mean);
        }
        mean_ate[config] = ComputeMeanStd(means).mean;
      }
      const std::string baseline = groups.front().baseline;
      for (const auto& config : configs) {
        std::string cell = fmt::format("{:.4f}", mean_ate[config]);
        const auto b = mean_ate.find(baseline);
        if (config != baseline && b != mean_ate.end() && b->second > 0) {
          cell += " (" + Percent(100.0 * (mean_ate[config] - b->second) / b->second) + ")";
        }
        mean_row.push_back(cell);
        const auto it = changes.find(config);
        avg_row.push_back(it == changes.end() ? "" : Percent(ComputeMeanStd(it->second).mean));
        if (it == changes.end()) {
          wins_row.push_back("");
        } else {
          const auto wins =
              std::count_if(it->second.begin(), it->second.end(), [](double p) { return p < 0; });
          wins_row.push_back(fmt::format("{}/{}", wins, it->second.size()));
        }
      }
      t.rows.push_back(mean_row);
      t.rows.push_back(avg_row);
      t.rows.push_back(wins_row);
    }
    tables.push_back(t);
  }
  return tables;
}

Table DetailTable(const std::vector<GroupSummary>& groups) {
  Table t;
  t.title = "Per configuration: keyframes, map, losses and run time (mean ± std over runs)";
  t.header = {"dataset",
              "sensor",
              "config",
              "ok/runs",
              "ATE [m]",
              "RPE [m]",
              "scale",
              "coverage",
              "keyframes",
              "map points",
              "lost frames",
              "wall [s]",
              "median tracking [ms]"};
  for (const auto& g : groups) {
    t.rows.push_back({g.dataset, g.sensor, g.config, fmt::format("{}/{}", g.ok, g.runs),
                      FormatMeanStd(g.ate_m, 4), FormatMeanStd(g.rpe_trans_m, 4),
                      FormatMeanStd(g.scale, 3),
                      g.coverage.n > 0 ? fmt::format("{:.0f}%", 100.0 * g.coverage.mean) : "—",
                      FormatMeanStd(g.keyframes, 1), FormatMeanStd(g.map_points, 0),
                      FormatMeanStd(g.lost_frames, 1), FormatMeanStd(g.wall_s, 1),
                      FormatMeanStd(g.median_tracking_ms, 1)});
  }
  return t;
}

namespace {

// The (dataset / sensor / selector) lines of a sweep on which no value changed the runs: the same
// keyframe count and ATE at every value (a parameter the selector does not read, or one whose
// range never reaches a decision). Said in the table so one flat line is not read as a result.
std::vector<std::string> SweepLinesWithoutEffect(const std::vector<GroupSummary>& groups,
                                                 const std::string& param) {
  std::map<std::string, std::vector<const GroupSummary*>> lines;
  for (const auto& g : groups) {
    if (g.sweep_param == param) lines[g.dataset + "/" + g.sensor + "/" + g.selector].push_back(&g);
  }
  std::vector<std::string> flat;
  for (const auto& [name, points] : lines) {
    if (points.size() < 2) continue;
    const GroupSummary& first = *points.front();
    const bool same = std::all_of(points.begin(), points.end(), [&](const GroupSummary* g) {
      return g->ok == g->runs && g->keyframes.mean == first.keyframes.mean &&
             g->ate_m.mean == first.ate_m.mean;
    });
    if (same) flat.push_back(name);
  }
  return flat;
}

}  // namespace

std::vector<Table> SweepTables(const std::vector<GroupSummary>& groups) {
  std::vector<std::string> params;
  for (const auto& g : groups) {
    if (!g.sweep_param.empty() &&
        std::find(params.begin(), params.end(), g.sweep_param) == params.end()) {
      params.push_back(g.sweep_param);
    }
  }
  std::vector<Table> tables;
  for (const auto& p : params) {
    Table t;
    t.title = "Sweep of " + p;
    const std::vector<std::string> flat = SweepLinesWithoutEffect(groups, p);
    if (!flat.empty()) {
      t.title += fmt::format(
          " (no value of {} changed the runs of {}: the same keyframes and ATE at every value, so "
          "the parameter did not act there)",
          p, fmt::join(flat, ", "));
    }
    t.header = {"dataset", "sensor", "config", p, "ATE [m]", "keyframes", "ok/runs"};
    const bool dense = std::any_of(groups.begin(), groups.end(), [&](const GroupSummary& g) {
      return g.sweep_param == p && g.dense_points.n > 0;
    });
    if (dense) {
      t.title += " (Eq. 13: normalised dense points - normalised ATE, largest is best)";
      t.header.insert(t.header.end(), {"dense points", "Eq. 13 score"});
    }
    for (const auto& g : groups) {
      if (g.sweep_param != p) continue;
      std::vector<std::string> row = {g.dataset,
                                      g.sensor,
                                      g.config,
                                      FormatNumber(g.sweep_value),
                                      FormatMeanStd(g.ate_m, 4),
                                      FormatMeanStd(g.keyframes, 1),
                                      fmt::format("{}/{}", g.ok, g.runs)};
      if (dense) {
        bool best = std::isfinite(g.sweep_score);
        for (const auto& o : groups) {
          if (o.dataset == g.dataset && o.sensor == g.sensor && o.selector == g.selector &&
              o.sweep_param == p && std::isfinite(o.sweep_score) && o.sweep_score > g.sweep_score) {
            best = false;
          }
        }
        row.push_back(FormatMeanStd(g.dense_points, 0));
        row.push_back(std::isfinite(g.sweep_score)
                          ? fmt::format("{:+.2f}{}", g.sweep_score, best ? " (best)" : "")
                          : "—");
      }
      t.rows.push_back(std::move(row));
    }
    tables.push_back(t);
  }
  return tables;
}

Table BiasTable(const std::vector<GroupSummary>& groups) {
  Table t;
  t.title =
      "IMU bias estimates: relative error [%] of the keyframes' gyro and accelerometer biases "
      "from 15 s after the first keyframe, mean ± std over runs";
  t.header = {"dataset", "sensor", "config", "gyro bias error [%]", "accel bias error [%]"};
  for (const auto& g : groups) {
    if (g.gyro_bias_err_pct.n == 0) continue;
    t.rows.push_back({g.dataset, g.sensor, g.config, FormatMeanStd(g.gyro_bias_err_pct, 1),
                      FormatMeanStd(g.accel_bias_err_pct, 1)});
  }
  return t;
}

Table SpeedTable(const std::vector<GroupSummary>& groups) {
  Table t;
  t.title =
      "Speed: median over the successful runs (realtime factor = sequence duration / wall time, "
      "> 1 is faster than real time)";
  t.header = {"dataset",           "sensor",          "config",
              "ok/runs",           "realtime factor", "median tracking [ms]",
              "p95 tracking [ms]", "mapping [ms/KF]", "CPU [s]",
              "peak memory [MiB]"};
  const bool measured = std::any_of(groups.begin(), groups.end(), [](const GroupSummary& g) {
    return std::isfinite(g.speed.realtime_factor);
  });
  if (!measured) return t;
  std::vector<std::string> peers;
  for (const auto& g : groups) {
    if (g.selector == "peer" && std::find(peers.begin(), peers.end(), g.config) == peers.end()) {
      peers.push_back(g.config);
    }
  }
  for (const auto& peer : peers) t.header.push_back("RT pkslam/" + peer);
  for (const auto& g : groups) {
    const SpeedMedians& s = g.speed;
    std::vector<std::string> row = {g.dataset,
                                    g.sensor,
                                    g.config,
                                    fmt::format("{}/{}", g.ok, g.runs),
                                    Fixed(s.realtime_factor, 2),
                                    Fixed(s.tracking_ms, 1),
                                    Fixed(s.p95_tracking_ms, 1),
                                    Fixed(s.mapping_ms_per_kf, 1),
                                    Fixed(s.cpu_s, 1),
                                    Fixed(s.peak_memory_mib, 0)};
    for (const auto& peer : peers) {
      const double ratio = RealtimeRatio(g, peer, groups);
      row.push_back(std::isfinite(ratio) ? fmt::format("{:.2f}", ratio) : "");
    }
    t.rows.push_back(std::move(row));
  }
  return t;
}

Table FailureTable(const std::vector<RunResult>& results) {
  Table t;
  t.title = "Failed runs";
  t.header = {"run", "error"};
  for (const auto& r : results) {
    if (!r.ok) t.rows.push_back({r.run_id, r.error});
  }
  return t;
}

Table ReasonTable(const std::vector<RunResult>& results) {
  struct Counts {
    std::string sensor;
    std::string config;
    int runs = 0;
    std::map<std::string, double> per_rule;
    double mentions = 0;
  };
  std::vector<Counts> groups;  // in matrix order
  std::vector<std::string> rules;
  for (const auto& r : results) {
    if (!r.ok || r.keyframe_reasons.empty() || !r.sweep_param.empty()) continue;
    auto it = std::find_if(groups.begin(), groups.end(), [&](const Counts& c) {
      return c.sensor == r.sensor && c.config == r.config;
    });
    if (it == groups.end()) {
      Counts fresh;
      fresh.sensor = r.sensor;
      fresh.config = r.config;
      it = groups.insert(groups.end(), std::move(fresh));
    }
    ++it->runs;
    std::stringstream items(r.keyframe_reasons);
    std::string item;
    while (items >> item) {
      const auto eq = item.rfind('=');
      if (eq == std::string::npos) continue;
      const double n = std::atof(item.c_str() + eq + 1);
      std::string reason = item.substr(0, eq);
      reason = reason.substr(0, reason.find(';'));
      std::stringstream parts(reason);
      std::string rule;
      while (std::getline(parts, rule, '+')) {
        if (rule.empty()) continue;
        if (std::find(rules.begin(), rules.end(), rule) == rules.end()) rules.push_back(rule);
        it->per_rule[rule] += n;
        it->mentions += n;
      }
    }
  }
  Table t;
  t.title = "Keyframes per run by the rule that created them (share of rule mentions)";
  t.header = {"sensor", "configuration", "runs"};
  t.header.insert(t.header.end(), rules.begin(), rules.end());
  for (const auto& g : groups) {
    std::vector<std::string> row = {g.sensor, g.config, std::to_string(g.runs)};
    for (const auto& rule : rules) {
      const auto it = g.per_rule.find(rule);
      row.push_back(it == g.per_rule.end()
                        ? "—"
                        : fmt::format("{:.1f} ({:.0f}%)", it->second / g.runs,
                                      100.0 * it->second / std::max(1.0, g.mentions)));
    }
    t.rows.push_back(std::move(row));
  }
  return t;
}

std::string MarkdownTable(const Table& table) {
  auto cell = [](std::string* out, const std::string& text) {
    out->append(" ");
    for (char ch : text) {
      if (ch == '|') out->push_back('\\');
      out->push_back(ch);
    }
    out->append(" |");
  };
  std::string out = "|";
  for (const auto& h : table.header) cell(&out, h);
  out.append("\n|");
  for (std::size_t i = 0; i < table.header.size(); ++i) out.append(i == 0 ? " --- |" : " ---: |");
  out.append("\n");
  for (const auto& row : table.rows) {
    out.append("|");
    for (const auto& c : row) cell(&out, c);
    out.append("\n");
  }
  return out;
}

}  // namespace pkslam::bench
