#include "bench/report.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <map>
#include <sstream>

#include "bench/process.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/output_file.h"
#include "core/util/output_guard.h"
#include "core/util/project_file.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

struct Plot {
  fs::path file;  // relative to OUT
  std::string section;
  std::string caption;
};

std::string Html(const std::string& s) {
  std::string out;
  for (char ch : s) {
    switch (ch) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

// Runs plots.py; it writes PNGs and plots/index.tsv (file, section, caption per line).
std::vector<Plot> DrawPlots(const ReportOptions& o, const std::vector<fs::path>& roots,
                            std::string* error) {
  const fs::path script = o.plots_script.empty() ? DefaultPlotsScript() : o.plots_script;
  const fs::path dir = o.out / "plots";
  // Only a plots folder the bench made is replaced (index.tsv: one from before the marker).
  RemoveOwnedDirectory(dir, "index.tsv");
  CreateOwnedDirectory(dir);
  if (!fs::exists(o.python)) {
    *error = "python not found: " + o.python.string();
    return {};
  }
  if (!fs::exists(script)) {
    *error = "plot script not found: " + script.string();
    return {};
  }
  std::vector<std::string> argv = {o.python.string(), script.string(),
                                   "--results",       (o.out / "results.csv").string(),
                                   "--out",           dir.string()};
  for (const auto& r : roots) argv.insert(argv.end(), {"--runs", r.string()});
  const fs::path log = o.out / "plots.log";
  fs::remove(log);
  const ProcessResult p = RunProcess(argv, log, 1800.0);
  if (!p.ok()) {
    std::ifstream in(log);
    std::string line, last;
    while (std::getline(in, line)) {
      if (!line.empty()) last = line;
    }
    *error = fmt::format("plots.py failed ({}): {} (see {})", p.Describe(), last, log.string());
    return {};
  }
  std::vector<Plot> plots;
  std::ifstream index(dir / "index.tsv");
  std::string line;
  while (std::getline(index, line)) {
    std::stringstream ss(line);
    Plot plot;
    std::string file;
    if (!std::getline(ss, file, '\t') || !std::getline(ss, plot.section, '\t')) continue;
    std::getline(ss, plot.caption);
    plot.file = fs::path("plots") / file;
    if (fs::exists(o.out / plot.file)) plots.push_back(plot);
  }
  return plots;
}

struct Document {
  std::string md;
  std::string html;

  void Heading(int level, const std::string& text) {
    md += std::string(level, '#') + " " + text + "\n\n";
    html += fmt::format("<h{0}>{1}</h{0}>\n", level, Html(text));
  }
  void Paragraph(const std::string& text) {
    md += text + "\n\n";
    html += "<p>" + Html(text) + "</p>\n";
  }
  void AddTable(const Table& t) {
    if (!t.title.empty()) {
      md += "**" + t.title + "**\n\n";
      html += "<p><b>" + Html(t.title) + "</b></p>\n";
    }
    md += MarkdownTable(t) + "\n";
    html += HtmlTable(t);
  }
  void Image(const Plot& p) {
    md += fmt::format("![{}]({})\n\n*{}*\n\n", p.caption, p.file.string(), p.caption);
    html += fmt::format("<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>\n",
                        Html(p.file.string()), Html(p.caption), Html(p.caption));
  }
  void Images(const std::vector<Plot>& plots, const std::string& section) {
    for (const auto& p : plots) {
      if (p.section == section) Image(p);
    }
  }
};

// Links to each run's viewer page (RUN/view.html, written when the run was evaluated).
void AddRunViews(Document* doc, const std::vector<RunResult>& results, const ReportOptions& o) {
  const auto roots = o.run_roots.empty() ? std::vector<fs::path>{o.out / "runs"} : o.run_roots;
  std::string rows;
  std::string md;
  int pages = 0;
  for (const RunResult& r : results) {
    for (const fs::path& root : roots) {
      const fs::path page = root / r.run_id / "view.html";
      if (!fs::exists(page)) continue;
      const std::string link = fs::relative(page, o.out).generic_string();
      const std::string ate = std::isfinite(r.ate_m) ? fmt::format("{:.4f}", r.ate_m) : "-";
      rows += fmt::format("<tr><td><a href=\"{}\">{}</a></td><td>{}</td></tr>\n", Html(link),
                          Html(r.run_id), ate);
      md += fmt::format("- [{}]({}) ATE {}\n", r.run_id, link, ate);
      ++pages;
      break;
    }
  }
  if (pages == 0) return;
  doc->Heading(2, "Runs in 3-D");
  doc->Paragraph(
      "Each run's viewer page (pkslam view): the trajectory coloured by its ATE over the ground "
      "truth, keyframes coloured by the rule that created them, map points, and a timeline of "
      "tracking state and keyframe decisions.");
  doc->md += md + "\n";
  doc->html += fmt::format(
      "<details><summary>{} runs</summary>\n<table>\n<tr><th>run</th><th>ATE (m)</th></tr>\n{}"
      "</table></details>\n",
      pages, rows);
}

// The Speed section, when the runs measured their speed (pkslam run's stats.json since
// realtime_factor; peers through peer_import.cc).
void AddSpeed(Document* doc, const std::vector<GroupSummary>& groups) {
  const Table speed = SpeedTable(groups);
  if (speed.rows.empty()) return;
  doc->Heading(2, "Speed");
  std::string text =
      "Timings compare only between runs on an otherwise idle machine (--jobs 1). pkslam's wall "
      "time is its frame loop (after loading the vocabulary); mapping [ms/KF] is the median local "
      "mapping time per keyframe; CPU is the whole process's (every thread).";
  const bool peers = std::any_of(groups.begin(), groups.end(),
                                 [](const GroupSummary& g) { return g.selector == "peer"; });
  if (peers) {
    text +=
        " A peer's realtime factor is over its frame loop: the sum of its per-frame Track*() "
        "times (it decodes images outside them, and loads its vocabulary before); its CPU is "
        "its whole process's; RT pkslam/PEER is the ratio of realtime factors on the same "
        "dataset and sensor (> 1: pkslam is faster).";
  }
  doc->Paragraph(text);
  doc->AddTable(speed);
}

// The Statistics section plots.py wrote with bench_statistics.py (tests, intervals, power).
void AddStatistics(Document* doc, const fs::path& plots_dir) {
  const fs::path md = plots_dir / "statistics.md";
  const fs::path html = plots_dir / "statistics.html";
  if (!fs::exists(md) || !fs::exists(html)) return;
  auto slurp = [](const fs::path& file) {
    std::ifstream in(file);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  doc->Heading(2, "Statistics");
  doc->md += slurp(md) + "\n";
  doc->html += slurp(html);
}

std::string Now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buffer[64];
  std::strftime(buffer, sizeof(buffer), "%Y-%m-%d %H:%M UTC", &tm);
  return buffer;
}

const char* kHtmlHead = R"(<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{}</title>
<style>
body {{ font-family: sans-serif; max-width: 1200px; margin: 2em auto; padding: 0 1em;
  color: #222; }}
.wide {{ overflow-x: auto; }}
table {{ border-collapse: collapse; margin: 0.5em 0 1.5em; font-size: 0.85em; }}
tr:nth-child(even) td {{ background: #fafafa; }}
th, td {{ border: 1px solid #bbb; padding: 0.25em 0.6em; text-align: right; }}
th:first-child, td:first-child {{ text-align: left; }}
th {{ background: #eee; }}
figure {{ margin: 1em 0; }} img {{ max-width: 100%; }}
figcaption {{ font-style: italic; color: #555; }}
</style></head><body>
)";

}  // namespace

fs::path DefaultPlotsScript() { return FindProjectFile("bench/plots.py"); }

std::string HtmlTable(const Table& table) {
  // Wide tables scroll inside their own box on a laptop screen instead of widening the page.
  std::string out = "<div class=\"wide\"><table>\n<tr>";
  for (const auto& h : table.header) out += "<th>" + Html(h) + "</th>";
  out += "</tr>\n";
  for (const auto& row : table.rows) {
    out += "<tr>";
    for (const auto& c : row) out += "<td>" + Html(c) + "</td>";
    out += "</tr>\n";
  }
  return out + "</table></div>\n";
}

ReportFiles WriteReport(std::vector<RunResult> results, const ReportOptions& options) {
  std::sort(results.begin(), results.end(),
            [](const RunResult& a, const RunResult& b) { return a.index < b.index; });
  fs::create_directories(options.out);
  WriteResultsCsv(options.out / "results.csv", results);
  const std::vector<GroupSummary> groups = Summarize(results);
  WriteSummaryCsv(options.out / "summary.csv", groups);

  ReportFiles files;
  std::vector<Plot> plots;
  if (options.plots) {
    const auto roots =
        options.run_roots.empty() ? std::vector<fs::path>{options.out / "runs"} : options.run_roots;
    plots = DrawPlots(options, roots, &files.plot_error);
    for (const auto& p : plots) files.pngs.push_back(options.out / p.file);
    if (!files.plot_error.empty()) PKSLAM_LOG_WARN("no plots: {}", files.plot_error);
  }

  const int ok = static_cast<int>(
      std::count_if(results.begin(), results.end(), [](const RunResult& r) { return r.ok; }));
  std::string baseline = results.empty() ? "" : results.front().baseline;
  Document doc;
  doc.Heading(1, options.title);
  doc.Paragraph(fmt::format(
      "{} runs ({} succeeded, {} failed) in {} configurations; generated {}. ATE is the RMSE of "
      "positions after the alignment each table names (results.csv has both SE(3) and Sim(3)); "
      "ATE change = 100 · (ATE − ATE_{}) / ATE_{} on the means over runs, negative = lower error: "
      "the one sign used by every table, plot and sentence below. [cov N%] flags a "
      "configuration whose evaluated trajectory (the largest map) holds fewer than 90% of the "
      "frames: its ATE covers only that part and is not comparable. Data: results.csv (one row "
      "per run), summary.csv (one row per configuration).",
      results.size(), ok, results.size() - ok, groups.size(), Now(), baseline, baseline));
  doc.Heading(2, "Accuracy");
  for (const auto& t : HeadlineTables(groups)) doc.AddTable(t);
  doc.Images(plots, "accuracy");
  AddStatistics(&doc, options.out / "plots");
  if (std::any_of(plots.begin(), plots.end(),
                  [](const Plot& p) { return p.section == "budget"; })) {
    doc.Heading(2, "Equal keyframe budget");
    doc.Paragraph(
        "A selector that takes more keyframes may be more accurate for that reason alone: each "
        "selector's swept parameter moves it along a line of ATE against keyframe rate and "
        "mapping cost; compare selectors where their lines overlap in x.");
    doc.Images(plots, "budget");
  }
  doc.Heading(2, "Trajectories");
  doc.Paragraph(
      "Top view (x-y) of ground truth and the median-ATE run of each configuration, "
      "aligned as above; dots mark keyframes.");
  doc.Images(plots, "trajectories");
  doc.Heading(2, "Keyframes, maps and run time");
  doc.AddTable(DetailTable(groups));
  if (const Table reasons = ReasonTable(results); !reasons.rows.empty()) doc.AddTable(reasons);
  doc.Images(plots, "keyframes");
  AddSpeed(&doc, groups);
  const Table biases = BiasTable(groups);
  if (!biases.rows.empty()) {
    doc.Heading(2, "IMU biases");
    doc.AddTable(biases);
  }
  const auto sweeps = SweepTables(groups);
  if (!sweeps.empty()) {
    doc.Heading(2, "Parameter sweeps");
    for (const auto& t : sweeps) doc.AddTable(t);
    doc.Images(plots, "sweeps");
  }
  if (std::any_of(plots.begin(), plots.end(),
                  [](const Plot& p) { return p.section == "calibration"; })) {
    doc.Heading(2, "Online calibration");
    doc.Paragraph(
        "The calibration estimates of runs with --calibrate online over the flight "
        "(docs/calibration.md); each run's final estimate with sigmas is in its stats.json.");
    doc.Images(plots, "calibration");
  }
  const Table failures = FailureTable(results);
  if (!failures.rows.empty()) {
    doc.Heading(2, "Failed runs");
    doc.AddTable(failures);
  }
  AddRunViews(&doc, results, options);
  if (!files.plot_error.empty()) doc.Paragraph("Plots unavailable: " + files.plot_error);

  WriteFileAtomically(options.out / "report.md", doc.md);
  WriteFileAtomically(
      options.out / "report.html",
      fmt::format(fmt::runtime(kHtmlHead), Html(options.title)) + doc.html + "</body></html>\n");
  return files;
}

std::vector<RunResult> CollectResults(const std::vector<fs::path>& dirs) {
  std::map<std::string, RunResult> by_id;
  for (const auto& dir : dirs) {
    if (fs::is_regular_file(dir)) {  // a recorded collection (its results.csv)
      for (auto& r : ReadResultsCsv(dir)) by_id[r.run_id] = std::move(r);
      continue;
    }
    const fs::path runs = dir / "runs";
    if (!fs::is_directory(runs)) throw InputError(dir, "no runs/ folder to collect");
    for (const auto& entry : fs::recursive_directory_iterator(runs)) {
      if (entry.path().filename() != "result.csv") continue;
      for (auto& r : ReadResultsCsv(entry.path())) by_id[r.run_id] = std::move(r);
    }
  }
  std::vector<RunResult> out;
  for (auto& [id, r] : by_id) out.push_back(std::move(r));
  std::sort(out.begin(), out.end(),
            [](const RunResult& a, const RunResult& b) { return a.index < b.index; });
  return out;
}

}  // namespace pkslam::bench
