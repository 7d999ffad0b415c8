// Histogram PNG of cloud-comparison distances, drawn by dense/plot_cloud_histogram.py with the
// system Python (/usr/bin/python3 with matplotlib and numpy: Debian python3-matplotlib).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace pkslam::dense {

struct HistogramSeries {
  std::string label;
  std::vector<float> distances_m;
};

// The plotting script shipped with pkslam (source tree), or an empty path when absent.
std::filesystem::path HistogramScriptPath();

// Plots each series' distance histogram (cm, clipped at max_cm) into `png`. Throws Error when
// Python, matplotlib or the script is missing or the plot fails (the message says which).
void PlotDistanceHistograms(const std::vector<HistogramSeries>& series, const std::string& title,
                            double max_cm, const std::filesystem::path& png);

}  // namespace pkslam::dense
