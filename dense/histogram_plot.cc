#include "dense/histogram_plot.h"

#include <fmt/format.h>
#include <stdlib.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/util/error.h"
#include "core/util/project_file.h"

namespace pkslam::dense {

namespace fs = std::filesystem;

namespace {

constexpr const char* kPython = "/usr/bin/python3";  // Debian's, with numpy and matplotlib

std::string ShellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  return out + "'";
}

}  // namespace

fs::path HistogramScriptPath() {
  const fs::path script = FindProjectFile("dense/plot_cloud_histogram.py");
  return fs::exists(script) ? script : fs::path();
}

void PlotDistanceHistograms(const std::vector<HistogramSeries>& series, const std::string& title,
                            double max_cm, const fs::path& png) {
  PKSLAM_CHECK(!series.empty() && max_cm > 0, "nothing to plot");
  const fs::path script = HistogramScriptPath();
  if (script.empty()) throw Error("histogram: dense/plot_cloud_histogram.py not found");
  if (!fs::exists(kPython)) throw Error(fmt::format("histogram: {} not found", kPython));
  std::string pattern = (fs::temp_directory_path() / "pkslam_hist_XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) throw Error("histogram: cannot create a temp directory");
  const fs::path tmp = pattern;
  struct Cleanup {
    fs::path dir;
    ~Cleanup() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } cleanup{tmp};
  std::string command = fmt::format("{} {} {} {} {:g}", kPython, ShellQuote(script.string()),
                                    ShellQuote(png.string()), ShellQuote(title), max_cm);
  for (std::size_t i = 0; i < series.size(); ++i) {
    const fs::path data = tmp / fmt::format("series{}.f32", i);
    std::ofstream out(data, std::ios::binary);
    out.write(reinterpret_cast<const char*>(series[i].distances_m.data()),
              static_cast<std::streamsize>(series[i].distances_m.size() * sizeof(float)));
    if (!out) throw Error("histogram: cannot write the temporary data file");
    command += fmt::format(" {} {}", ShellQuote(series[i].label), ShellQuote(data.string()));
  }
  const fs::path log = tmp / "log.txt";
  command += " > " + ShellQuote(log.string()) + " 2>&1";
  const int rc = std::system(command.c_str());
  if (rc != 0) {
    std::ifstream in(log);
    std::string last, line;
    while (std::getline(in, line)) {
      if (!line.empty()) last = line;
    }
    throw Error(fmt::format("histogram: the plot script failed ({})", last));
  }
}

}  // namespace pkslam::dense
