#include "io/tum_rgbd_dataset.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <tuple>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/quantile.h"
#include "io/opencv_yaml.h"
#include "io/text_rows.h"

namespace pkslam {

namespace fs = std::filesystem;

void TumRgbdOptions::Check() const {
  PKSLAM_CHECK_OPTION(max_difference_s > 0 && max_difference_s < 10, "max_difference_s", "{}",
                      max_difference_s);
  PKSLAM_CHECK_OPTION(depth_factor >= 0, "depth_factor", "{}", depth_factor);
  PKSLAM_CHECK_OPTION(nominal_rate_hz > 0, "nominal_rate_hz", "{}", nominal_rate_hz);
  PKSLAM_CHECK_OPTION(frame_gap_periods > 1.0, "frame_gap_periods", "{}", frame_gap_periods);
}

std::vector<ImageEntry> ReadTumImageList(const fs::path& list_file) {
  std::vector<ImageEntry> entries;
  std::optional<std::int64_t> previous;
  const fs::path dir = list_file.parent_path();
  const std::size_t rows =
      ForEachDataRow(list_file, FieldSeparator::kWhitespace, [&](const TextRow& r) {
        RequireFieldCount(r, 2, list_file, "timestamp filename");
        const std::int64_t t_ns = SecondsFieldToNs(r.fields[0], list_file, r.line, "timestamp");
        RequireIncreasing(previous, t_ns, list_file, r.line);
        previous = t_ns;
        entries.push_back({t_ns, dir / std::string(r.fields[1])});
      });
  if (rows == 0) throw InputError(list_file, "no data rows (empty file)");
  return entries;
}

std::vector<TumGroundTruthPose> ReadTumGroundTruth(const fs::path& file) {
  std::vector<TumGroundTruthPose> poses;
  std::optional<std::int64_t> previous;
  const std::size_t rows = ForEachDataRow(file, FieldSeparator::kWhitespace, [&](const TextRow& r) {
    RequireFieldCount(r, 8, file, "timestamp tx ty tz qx qy qz qw");
    TumGroundTruthPose pose;
    pose.t_ns = SecondsFieldToNs(r.fields[0], file, r.line, "timestamp");
    RequireIncreasing(previous, pose.t_ns, file, r.line);
    previous = pose.t_ns;
    double v[7];
    for (int k = 0; k < 7; ++k) {
      v[k] = DoubleField(r.fields[1 + k], file, r.line, fmt::format("column {}", k + 2));
    }
    const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);  // stored x, y, z, w
    if (std::abs(q.norm() - 1.0) > 1e-2) {
      throw InputError(file, r.line, fmt::format("quaternion norm {:.6f} is not 1", q.norm()));
    }
    pose.world_from_camera = SE3d(q.normalized(), Eigen::Vector3d(v[0], v[1], v[2]));
    poses.push_back(pose);
  });
  if (rows == 0) throw InputError(file, "no data rows (empty file)");
  return poses;
}

std::vector<std::pair<std::size_t, std::size_t>> AssociateTimestamps(
    const std::vector<std::int64_t>& a_ns, const std::vector<std::int64_t>& b_ns,
    std::int64_t max_difference_ns) {
  // Candidates (|difference|, i, j); b is sorted, so each a only looks at a window of b.
  std::vector<std::tuple<std::int64_t, std::size_t, std::size_t>> candidates;
  // The window bounds in 128 bits: a +- max overflowed int64 for timestamps near its ends.
  for (std::size_t i = 0; i < a_ns.size(); ++i) {
    const __int128 low = static_cast<__int128>(a_ns[i]) - max_difference_ns;
    const __int128 high = static_cast<__int128>(a_ns[i]) + max_difference_ns;
    auto j = std::upper_bound(b_ns.begin(), b_ns.end(), low,
                              [](__int128 bound, std::int64_t b) { return bound < b; });
    for (; j != b_ns.end() && *j < high; ++j) {
      candidates.emplace_back(std::abs(*j - a_ns[i]), i,
                              static_cast<std::size_t>(j - b_ns.begin()));
    }
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<bool> a_used(a_ns.size(), false);
  std::vector<bool> b_used(b_ns.size(), false);
  std::vector<std::pair<std::size_t, std::size_t>> matches;
  for (const auto& [difference, i, j] : candidates) {
    if (a_used[i] || b_used[j]) continue;
    a_used[i] = true;
    b_used[j] = true;
    matches.emplace_back(i, j);
  }
  std::sort(matches.begin(), matches.end());
  return matches;
}

bool TumRgbdDataset::LooksLikeTumRgbd(const fs::path& root) {
  std::error_code ec;
  return fs::is_regular_file(root / "rgb.txt", ec) && fs::is_regular_file(root / "depth.txt", ec);
}

TumRgbdDataset TumRgbdDataset::Open(const fs::path& root, const TumRgbdOptions& options) {
  options.Check();
  if (!fs::exists(root)) throw InputError(root, "dataset directory not found");
  TumRgbdDataset d;
  d.root_ = root;
  const auto read_stream = [&](const char* name) {
    ImageStream stream;
    stream.name = name;
    stream.list_file = root / fmt::format("{}.txt", name);
    stream.nominal_rate_hz = options.nominal_rate_hz;
    FillImageStream(ReadTumImageList(stream.list_file), options.frame_gap_periods, &stream);
    return stream;
  };
  d.rgb_ = read_stream("rgb");
  d.depth_ = read_stream("depth");

  std::vector<std::int64_t> rgb_t;
  std::vector<std::int64_t> depth_t;
  for (const ImageEntry& e : d.rgb_.images) rgb_t.push_back(e.t_ns);
  for (const ImageEntry& e : d.depth_.images) depth_t.push_back(e.t_ns);
  // Round the tolerance to whole ns; the comparison itself stays in integers.
  const auto max_difference_ns =
      static_cast<std::int64_t>(std::llround(options.max_difference_s * 1e9));
  for (const auto& [i, j] : AssociateTimestamps(rgb_t, depth_t, max_difference_ns)) {
    d.associations_.push_back({i, j});
  }

  const fs::path gt = root / "groundtruth.txt";
  if (fs::is_regular_file(gt)) d.ground_truth_ = ReadTumGroundTruth(gt);

  d.depth_factor_ = 5000;
  if (options.depth_factor > 0) {
    d.depth_factor_ = options.depth_factor;
  } else if (fs::is_regular_file(root / "settings.yaml")) {
    const OpenCvYamlFile settings(root / "settings.yaml");
    if (const auto factor = settings.OptionalDouble("RGBD.DepthMapFactor")) {
      if (!(*factor > 0)) settings.Fail("RGBD.DepthMapFactor", "must be positive");
      d.depth_factor_ = *factor;
    }
  }
  return d;
}

cv::Mat TumRgbdDataset::LoadRgbColour(std::size_t i) const {
  PKSLAM_CHECK(i < rgb_.images.size(), "rgb index {} of {}", i, rgb_.images.size());
  return LoadColourImage(rgb_.images[i].path);
}

cv::Mat TumRgbdDataset::LoadRgbGrey(std::size_t i) const {
  PKSLAM_CHECK(i < rgb_.images.size(), "rgb index {} of {}", i, rgb_.images.size());
  return LoadGreyImage(rgb_.images[i].path);
}

cv::Mat TumRgbdDataset::LoadDepthRaw(std::size_t i) const {
  PKSLAM_CHECK(i < depth_.images.size(), "depth index {} of {}", i, depth_.images.size());
  cv::Mat depth = LoadUnchangedImage(depth_.images[i].path);
  if (depth.type() != CV_16UC1) {
    throw InputError(depth_.images[i].path,
                     fmt::format("depth image must be 16-bit single channel, found {} channels "
                                 "of depth code {}",
                                 depth.channels(), depth.depth()));
  }
  return depth;
}

void TumRgbdDataset::RequireValidDepth(std::size_t images) const {
  const std::size_t n = std::min(images, associations_.size());
  for (std::size_t k = 0; k < n; ++k) {
    if (cv::countNonZero(LoadDepthRaw(associations_[k].depth)) > 0) return;
  }
  if (n == 0) return;
  throw InputError(depth_.images[associations_.front().depth].path,
                   fmt::format("this and the next {} depth images hold no valid depth (all "
                               "zero): check the depth images and the depth factor",
                               n - 1));
}

void TumRgbdDataset::CheckDepthScale(double factor, const std::string& factor_source,
                                     std::size_t images) const {
  const std::size_t n = std::min(images, associations_.size());
  std::vector<double> raw;
  for (std::size_t k = 0; k < n; ++k) {
    cv::Mat depth;
    LoadDepthRaw(associations_[k].depth).convertTo(depth, CV_32F);
    for (int r = 0; r < depth.rows; r += 4) {  // every 4th pixel: plenty for a median
      const float* row = depth.ptr<float>(r);
      for (int c = 0; c < depth.cols; c += 4) {
        if (row[c] > 0) raw.push_back(row[c]);
      }
    }
  }
  if (raw.empty() || factor <= 0) return;  // RequireValidDepth's and the settings' business
  const double raw_median = *Quantile(std::move(raw), 0.5);
  const double median_m = raw_median / factor;
  if (median_m >= 0.1 && median_m <= 50.0) return;
  throw InputError(depth_.images[associations_.front().depth].path,
                   fmt::format("median depth of the first {} depth images is {:.4g} m with {} "
                               "{:g} (raw median {:g}): the depth factor is wrong (TUM RGB-D: "
                               "5000 per metre; a sensor in millimetres: 1000)",
                               n, median_m, factor_source, factor, raw_median));
}

cv::Mat TumRgbdDataset::LoadDepthMetres(std::size_t i) const {
  cv::Mat metres;
  LoadDepthRaw(i).convertTo(metres, CV_32F, 1.0 / depth_factor_);
  return metres;
}

}  // namespace pkslam
