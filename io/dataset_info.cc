#include "io/dataset_info.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "core/util/json_writer.h"
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
  return fmt::format("camera {}x{} {} {}, fu fv cu cv = {} {} {} {}", c.width, c.height,
                     c.camera_model, c.distortion_model, c.intrinsics[0], c.intrinsics[1],
                     c.intrinsics[2], c.intrinsics[3]);
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
    info.stereo_baseline_m =
        (d.cam1_sensor().body_from_camera.Inverse() * d.cam0_sensor().body_from_camera)
            .translation()
            .norm();
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
    out += fmt::format("stereo pairs {} (cam0/cam1 with identical timestamps), baseline {:.6f} m\n",
                       GroupThousands(*info.stereo_pairs), info.stereo_baseline_m.value_or(0.0));
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
  JsonWriter json;
  json.BeginObject();
  json.Member("dataset", info.root.string());
  json.Member("layout", info.layout == DatasetLayout::kEuroc ? "euroc" : "tum_rgbd");
  json.Member("duration_s", info.ImageDurationS());
  json.Member("total_duration_s", info.TotalDurationS());
  json.Key("streams").BeginArray();
  for (const StreamSummary& s : info.streams) {
    json.BeginObject();
    json.Member("name", s.name);
    json.Member("description", s.description);
    json.Member("listed", static_cast<std::uint64_t>(s.listed));
    json.Member("count", static_cast<std::uint64_t>(s.count));
    json.Member("missing", static_cast<std::uint64_t>(s.missing_files.size()));
    json.Member("nominal_rate_hz", s.nominal_rate_hz);
    json.Member("measured_rate_hz", s.measured_rate_hz);
    json.Member("first_t_ns", s.first_ns);
    json.Member("last_t_ns", s.last_ns);
    json.Member("span_s", s.SpanS());
    json.Member("gap_threshold_periods", s.gap_threshold_periods);
    json.Key("missing_files").BeginArray();
    for (const std::string& f : s.missing_files) json.Value(f);
    json.EndArray();
    json.Key("gaps").BeginArray();
    for (const TimeGap& g : s.gaps) {
      json.BeginObject();
      json.Member("begin_t_ns", g.begin_ns);
      json.Member("end_t_ns", g.end_ns);
      json.Member("periods", g.periods);
      json.EndObject();
    }
    json.EndArray();
    json.EndObject();
  }
  json.EndArray();
  const auto optional_count = [&json](const char* key, const std::optional<std::size_t>& v) {
    json.Key(key);
    if (v) {
      json.Value(static_cast<std::uint64_t>(*v));
    } else {
      json.Null();
    }
  };
  optional_count("stereo_pairs", info.stereo_pairs);
  optional_count("rgbd_pairs", info.rgbd_pairs);
  if (info.stereo_baseline_m) json.Member("stereo_baseline_m", *info.stereo_baseline_m);
  if (info.rgbd_pairs)
    json.Member("association_max_difference_s", info.association_max_difference_s);
  if (info.depth_factor) json.Member("depth_factor", *info.depth_factor);
  const StreamSummary* gt = info.Find("groundtruth");
  json.Key("ground_truth").BeginObject();
  json.Member("present", info.has_ground_truth);
  json.Member("count", static_cast<std::uint64_t>(gt ? gt->count : 0));
  json.EndObject();
  json.EndObject();
  return json.str();
}

}  // namespace pkslam
