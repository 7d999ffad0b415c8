#include "io/dataset_info.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "io/euroc_dataset.h"
#include "io/tum_rgbd_dataset.h"

namespace pkslam {

namespace fs = std::filesystem;

DatasetLayout DetectDatasetLayout(const fs::path& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw InputError(dir, "dataset directory not found");
  if (!fs::is_directory(dir, ec)) throw InputError(dir, "not a directory");
  if (EurocDataset::LooksLikeEuroc(dir)) return DatasetLayout::kEuroc;
  if (TumRgbdDataset::LooksLikeTumRgbd(dir)) return DatasetLayout::kTumRgbd;
  if (fs::is_directory(dir / "mav0", ec)) {
    throw InputError(dir / "mav0" / "cam0" / "data.csv", "file not found (EuRoC needs cam0)");
  }
  throw InputError(dir,
                   "unknown dataset layout (expected mav0/cam0/data.csv for EuRoC ASL, or "
                   "rgb.txt and depth.txt for TUM RGB-D)");
}

std::string DatasetLayoutName(DatasetLayout layout) {
  return layout == DatasetLayout::kEuroc ? "EuRoC ASL" : "TUM RGB-D";
}

const StreamSummary* DatasetInfo::Find(const std::string& name) const {
  for (const StreamSummary& s : streams) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

double DatasetInfo::ImageDurationS() const {
  return streams.empty() ? 0.0 : streams.front().SpanS();
}

double DatasetInfo::TotalDurationS() const {
  std::optional<std::int64_t> first;
  std::optional<std::int64_t> last;
  for (const StreamSummary& s : streams) {
    if (s.count == 0) continue;
    first = first ? std::min(*first, s.first_ns) : s.first_ns;
    last = last ? std::max(*last, s.last_ns) : s.last_ns;
  }
  return first ? static_cast<double>(*last - *first) * 1e-9 : 0.0;
}

std::string GroupThousands(std::size_t n) {
  std::string digits = std::to_string(n);
  std::string out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

namespace {

StreamSummary SummariseImages(const ImageStream& stream, const std::string& description,
                              double gap_periods, const fs::path& root) {
  StreamSummary s;
  s.name = stream.name;
  s.description = description;
  s.listed = stream.listed;
  s.count = stream.images.size();
  s.nominal_rate_hz = stream.nominal_rate_hz;
  if (!stream.images.empty()) {
    s.first_ns = stream.images.front().t_ns;
    s.last_ns = stream.images.back().t_ns;
  }
  s.measured_rate_hz = MeasuredRateHz(s.first_ns, s.last_ns, s.count);
  s.gap_threshold_periods = gap_periods;
  s.gaps = stream.gaps;
  for (const fs::path& p : stream.missing)
    s.missing_files.push_back(p.lexically_relative(root).string());
  return s;
}

template <typename Sample>
StreamSummary SummariseSeries(const std::string& name, const std::string& description,
                              const std::vector<Sample>& samples, double nominal_rate_hz) {
  StreamSummary s;
  s.name = name;
  s.description = description;
  s.listed = s.count = samples.size();
  s.nominal_rate_hz = nominal_rate_hz;
  if (!samples.empty()) {
    s.first_ns = samples.front().t_ns;
    s.last_ns = samples.back().t_ns;
  }
  s.measured_rate_hz = MeasuredRateHz(s.first_ns, s.last_ns, s.count);
  return s;
}

std::string CameraDescription(const EurocCameraSensor& c) {
  return fmt::format("camera {}x{} {} {}", c.width, c.height, c.camera_model, c.distortion_model);
}

DatasetInfo EurocInfo(const fs::path& dir) {
  const EurocOptions options;
  const EurocDataset d = EurocDataset::Open(dir, options);
  DatasetInfo info;
  info.root = dir;
  info.layout = DatasetLayout::kEuroc;
  info.streams.push_back(SummariseImages(d.cam0(), CameraDescription(d.cam0_sensor()),
                                         options.frame_gap_periods, dir));
  if (d.has_cam1()) {
    info.streams.push_back(SummariseImages(d.cam1(), CameraDescription(d.cam1_sensor()),
                                           options.frame_gap_periods, dir));
    info.stereo_pairs = d.stereo_pairs().size();
  }
  if (d.has_imu()) {
    const EurocImuSensor& imu = d.imu_sensor();
    StreamSummary s = SummariseSeries(
        "imu0",
        fmt::format("imu gyro noise {:.4e} rad/s/sqrt(Hz), accel noise {:.4e} m/s^2/sqrt(Hz)",
                    imu.gyroscope_noise_density, imu.accelerometer_noise_density),
        d.imu(), imu.rate_hz);
    s.gap_threshold_periods = options.imu_gap_periods;
    s.gaps = d.imu_gaps();
    info.streams.push_back(std::move(s));
  }
  if (d.has_ground_truth()) {
    info.has_ground_truth = true;
    info.streams.push_back(SummariseSeries(
        "groundtruth", "state_groundtruth_estimate0 (p, q, v, b_w, b_a)", d.ground_truth(), 0));
  }
  return info;
}

DatasetInfo TumInfo(const fs::path& dir) {
  const TumRgbdOptions options;
  const TumRgbdDataset d = TumRgbdDataset::Open(dir, options);
  DatasetInfo info;
  info.root = dir;
  info.layout = DatasetLayout::kTumRgbd;
  info.streams.push_back(
      SummariseImages(d.rgb(), "colour images (rgb.txt)", options.frame_gap_periods, dir));
  info.streams.push_back(SummariseImages(
      d.depth(), fmt::format("16-bit depth images (depth.txt), {} per metre", d.depth_factor()),
      options.frame_gap_periods, dir));
  info.rgbd_pairs = d.associations().size();
  info.association_max_difference_s = options.max_difference_s;
  info.depth_factor = d.depth_factor();
  if (d.has_ground_truth()) {
    info.has_ground_truth = true;
    info.streams.push_back(SummariseSeries("groundtruth", "groundtruth.txt (t x y z qx qy qz qw)",
                                           d.ground_truth(), 0));
  }
  return info;
}

std::string Hz(double hz) { return hz > 0 ? fmt::format("{:g} Hz", hz) : "unknown"; }

std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += fmt::format("\\u{:04x}", static_cast<int>(c));
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string JsonNumber(double v) { return std::isfinite(v) ? fmt::format("{}", v) : "null"; }

}  // namespace

DatasetInfo ComputeDatasetInfo(const fs::path& dir) {
  return DetectDatasetLayout(dir) == DatasetLayout::kEuroc ? EurocInfo(dir) : TumInfo(dir);
}

std::string FormatDatasetInfo(const DatasetInfo& info) {
  std::string out;
  out += fmt::format("dataset      {}\nlayout       {}\n", info.root.string(),
                     DatasetLayoutName(info.layout));
  out += fmt::format("duration     {:.3f} s of images ({}), {:.3f} s over all streams\n",
                     info.ImageDurationS(), info.streams.front().name, info.TotalDurationS());
  for (const StreamSummary& s : info.streams) {
    const bool images = s.name != "imu0" && s.name != "groundtruth";
    out += fmt::format("{:<12} {}\n", s.name, s.description);
    out += fmt::format("{:<12} {} {}", "", GroupThousands(s.count), images ? "frames" : "samples");
    if (images) {
      out += fmt::format(" ({} listed, {} missing)", GroupThousands(s.listed),
                         GroupThousands(s.missing_files.size()));
    }
    out += fmt::format(", rate nominal {}, measured {:.3f} Hz, span {:.3f} s\n",
                       Hz(s.nominal_rate_hz), s.measured_rate_hz, s.SpanS());
  }
  if (info.stereo_pairs) {
    out += fmt::format("stereo pairs {} (cam0/cam1 with identical timestamps)\n",
                       GroupThousands(*info.stereo_pairs));
  }
  if (info.rgbd_pairs) {
    out += fmt::format("rgbd pairs   {} (rgb/depth associated within {:g} s)\n",
                       GroupThousands(*info.rgbd_pairs), info.association_max_difference_s);
  }
  if (!info.has_ground_truth) out += "groundtruth  none\n";

  std::size_t missing = 0;
  for (const StreamSummary& s : info.streams) missing += s.missing_files.size();
  out += fmt::format("missing      {} file{}\n", GroupThousands(missing), missing == 1 ? "" : "s");
  constexpr std::size_t kShown = 5;
  for (const StreamSummary& s : info.streams) {
    for (std::size_t i = 0; i < std::min(kShown, s.missing_files.size()); ++i) {
      out += fmt::format("             {}\n", s.missing_files[i]);
    }
    if (s.missing_files.size() > kShown) {
      out += fmt::format("             ... and {} more in {}\n", s.missing_files.size() - kShown,
                         s.name);
    }
  }
  for (const StreamSummary& s : info.streams) {
    if (s.gap_threshold_periods <= 0) continue;
    out += fmt::format("gaps {:<7} {} interval{} > {:g} nominal periods\n", s.name,
                       GroupThousands(s.gaps.size()), s.gaps.size() == 1 ? "" : "s",
                       s.gap_threshold_periods);
    for (std::size_t i = 0; i < std::min(kShown, s.gaps.size()); ++i) {
      const TimeGap& g = s.gaps[i];
      out += fmt::format("             {} -> {} ns ({:.3f} s, {:.1f} periods)\n", g.begin_ns,
                         g.end_ns, static_cast<double>(g.end_ns - g.begin_ns) * 1e-9, g.periods);
    }
    if (s.gaps.size() > kShown)
      out += fmt::format("             ... and {} more\n", s.gaps.size() - kShown);
  }
  return out;
}

std::string DatasetInfoToJson(const DatasetInfo& info) {
  std::string out = "{\n";
  out += fmt::format("  \"dataset\": {},\n  \"layout\": {},\n", JsonString(info.root.string()),
                     JsonString(info.layout == DatasetLayout::kEuroc ? "euroc" : "tum_rgbd"));
  out += fmt::format("  \"duration_s\": {},\n  \"total_duration_s\": {},\n",
                     JsonNumber(info.ImageDurationS()), JsonNumber(info.TotalDurationS()));
  out += "  \"streams\": [";
  for (std::size_t k = 0; k < info.streams.size(); ++k) {
    const StreamSummary& s = info.streams[k];
    out += k ? ",\n    {" : "\n    {";
    out += fmt::format(
        "\"name\": {}, \"description\": {}, \"listed\": {}, \"count\": {}, \"missing\": {}, "
        "\"nominal_rate_hz\": {}, \"measured_rate_hz\": {}, \"first_t_ns\": {}, "
        "\"last_t_ns\": {}, \"span_s\": {}, \"gap_threshold_periods\": {}, ",
        JsonString(s.name), JsonString(s.description), s.listed, s.count, s.missing_files.size(),
        JsonNumber(s.nominal_rate_hz), JsonNumber(s.measured_rate_hz), s.first_ns, s.last_ns,
        JsonNumber(s.SpanS()), JsonNumber(s.gap_threshold_periods));
    out += "\"missing_files\": [";
    for (std::size_t i = 0; i < s.missing_files.size(); ++i) {
      out += (i ? ", " : "") + JsonString(s.missing_files[i]);
    }
    out += "], \"gaps\": [";
    for (std::size_t i = 0; i < s.gaps.size(); ++i) {
      out +=
          fmt::format("{}{{\"begin_t_ns\": {}, \"end_t_ns\": {}, \"periods\": {}}}", i ? ", " : "",
                      s.gaps[i].begin_ns, s.gaps[i].end_ns, JsonNumber(s.gaps[i].periods));
    }
    out += "]}";
  }
  out += "\n  ],\n";
  const auto optional_count = [](const std::optional<std::size_t>& v) {
    return v ? std::to_string(*v) : std::string("null");
  };
  out += fmt::format("  \"stereo_pairs\": {},\n  \"rgbd_pairs\": {},\n",
                     optional_count(info.stereo_pairs), optional_count(info.rgbd_pairs));
  if (info.depth_factor)
    out += fmt::format("  \"depth_factor\": {},\n", JsonNumber(*info.depth_factor));
  const StreamSummary* gt = info.Find("groundtruth");
  out += fmt::format("  \"ground_truth\": {{\"present\": {}, \"count\": {}}}\n}}\n",
                     info.has_ground_truth ? "true" : "false", gt ? gt->count : 0);
  return out;
}

}  // namespace pkslam
