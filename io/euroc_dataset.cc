#include "io/euroc_dataset.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "core/util/log.h"
#include "io/kalibr_files.h"
#include "io/text_rows.h"

namespace pkslam {

namespace fs = std::filesystem;

void ImuLimits::Check() const {
  PKSLAM_CHECK_OPTION(max_gyro_rad_s > 0, "--imu-max-gyro", "{}", max_gyro_rad_s);
  PKSLAM_CHECK_OPTION(max_accel_m_s2 > 0, "--imu-max-accel", "{}", max_accel_m_s2);
}

void EurocOptions::Check() const {
  imu_limits.Check();
  PKSLAM_CHECK_OPTION(imu_gap_periods > 1.0, "imu_gap_periods", "{}", imu_gap_periods);
  PKSLAM_CHECK_OPTION(frame_gap_periods > 1.0, "frame_gap_periods", "{}", frame_gap_periods);
}

namespace {

void RequireRows(std::size_t rows, const fs::path& file) {
  if (rows == 0) throw InputError(file, "no data rows (empty file)");
}

Eigen::Vector3d Vec3Fields(const TextRow& row, std::size_t first, const fs::path& file,
                           const char* what) {
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) {
    v[k] = DoubleField(row.fields[first + k], file, row.line, fmt::format("{}[{}]", what, k));
  }
  return v;
}

fs::path ResolveMav0(const fs::path& root) {
  if (fs::is_directory(root / "mav0")) return root / "mav0";
  if (fs::is_regular_file(root / "cam0" / "data.csv")) return root;
  if (!fs::exists(root)) throw InputError(root, "dataset directory not found");
  throw InputError(root, "not a EuRoC ASL dataset (no mav0/ and no cam0/data.csv)");
}

ImageStream ReadCameraStream(const fs::path& dir, const std::string& name,
                             const EurocCameraSensor& sensor, double frame_gap_periods) {
  ImageStream stream;
  stream.name = name;
  stream.list_file = dir / "data.csv";
  stream.nominal_rate_hz = sensor.rate_hz;
  const std::vector<ImageEntry> listed = ReadEurocImageList(stream.list_file, dir / "data");
  FillImageStream(listed, frame_gap_periods, &stream);
  return stream;
}

}  // namespace

std::vector<ImageEntry> ReadEurocImageList(const fs::path& data_csv, const fs::path& image_dir) {
  std::vector<ImageEntry> entries;
  std::optional<std::int64_t> previous;
  const std::size_t rows = ForEachDataRow(data_csv, FieldSeparator::kComma, [&](const TextRow& r) {
    RequireFieldCount(r, 2, data_csv, "timestamp [ns],filename");
    const std::int64_t t_ns = Int64Field(r.fields[0], data_csv, r.line, "timestamp [ns]");
    RequireIncreasing(previous, t_ns, data_csv, r.line);
    previous = t_ns;
    if (r.fields[1].empty()) throw InputError(data_csv, r.line, "empty filename");
    entries.push_back({t_ns, image_dir / std::string(r.fields[1])});
  });
  RequireRows(rows, data_csv);
  return entries;
}

std::vector<ImuSample> ReadEurocImu(const fs::path& data_csv, const ImuLimits& limits) {
  std::vector<ImuSample> samples;
  std::optional<std::int64_t> previous;
  const std::size_t rows = ForEachDataRow(data_csv, FieldSeparator::kComma, [&](const TextRow& r) {
    RequireFieldCount(r, 7, data_csv, "timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z");
    ImuSample s;
    s.t_ns = Int64Field(r.fields[0], data_csv, r.line, "timestamp [ns]");
    RequireIncreasing(previous, s.t_ns, data_csv, r.line);
    previous = s.t_ns;
    s.gyro = Vec3Fields(r, 1, data_csv, "gyro");
    s.accel = Vec3Fields(r, 4, data_csv, "accel");
    // Beyond the sensor's range a value is not a measurement; a single 1e30 sample went into
    // the IMU initialisation (accelerometer bias ~1e28).
    if (s.gyro.cwiseAbs().maxCoeff() > limits.max_gyro_rad_s || !s.gyro.allFinite()) {
      throw InputError(data_csv, r.line,
                       fmt::format("gyro ({}, {}, {}) beyond +-{} rad/s (--imu-max-gyro): not a "
                                   "measurement in rad/s",
                                   s.gyro.x(), s.gyro.y(), s.gyro.z(), limits.max_gyro_rad_s));
    }
    if (s.accel.cwiseAbs().maxCoeff() > limits.max_accel_m_s2 || !s.accel.allFinite()) {
      throw InputError(data_csv, r.line,
                       fmt::format("accelerometer ({}, {}, {}) beyond +-{} m/s^2 "
                                   "(--imu-max-accel): not a measurement in m/s^2",
                                   s.accel.x(), s.accel.y(), s.accel.z(), limits.max_accel_m_s2));
    }
    samples.push_back(s);
  });
  RequireRows(rows, data_csv);
  return samples;
}

std::vector<EurocGroundTruthState> ReadEurocGroundTruth(const fs::path& data_csv) {
  std::vector<EurocGroundTruthState> states;
  std::optional<std::int64_t> previous;
  const std::size_t rows = ForEachDataRow(data_csv, FieldSeparator::kComma, [&](const TextRow& r) {
    RequireFieldCount(r, 17, data_csv, "timestamp [ns], p(3), q(w,x,y,z), v(3), b_w(3), b_a(3)");
    EurocGroundTruthState s;
    s.t_ns = Int64Field(r.fields[0], data_csv, r.line, "timestamp [ns]");
    RequireIncreasing(previous, s.t_ns, data_csv, r.line);
    previous = s.t_ns;
    const Eigen::Vector3d p = Vec3Fields(r, 1, data_csv, "position");
    double q[4];
    for (int k = 0; k < 4; ++k) {
      q[k] = DoubleField(r.fields[4 + k], data_csv, r.line, fmt::format("quaternion[{}]", k));
    }
    const Eigen::Quaterniond quat(q[0], q[1], q[2], q[3]);  // stored w, x, y, z
    if (std::abs(quat.norm() - 1.0) > 1e-2) {
      throw InputError(data_csv, r.line,
                       fmt::format("quaternion norm {:.6f} is not 1", quat.norm()));
    }
    s.world_from_body = SE3d(quat.normalized(), p);
    s.velocity_world = Vec3Fields(r, 8, data_csv, "velocity");
    s.gyro_bias = Vec3Fields(r, 11, data_csv, "gyro bias");
    s.accel_bias = Vec3Fields(r, 14, data_csv, "accel bias");
    states.push_back(s);
  });
  RequireRows(rows, data_csv);
  return states;
}

bool EurocDataset::LooksLikeEuroc(const fs::path& root) {
  std::error_code ec;
  return fs::is_regular_file(root / "mav0" / "cam0" / "data.csv", ec) ||
         fs::is_regular_file(root / "cam0" / "data.csv", ec);
}

namespace {

// A camera's sensor description: its sensor.yaml, or (TUM-VI's folders have none) entry
// `index` of Kalibr's camchain.yaml beside the dataset, with the rate from its data.csv.
EurocCameraSensor CameraSensorOf(const fs::path& mav0, const fs::path& dir, std::size_t index) {
  const auto camchain = FindKalibrCamchain(mav0);
  if (fs::exists(dir / "sensor.yaml") || !camchain) {
    return ReadEurocCameraSensor(dir / "sensor.yaml");
  }
  const std::vector<EurocCameraSensor> cameras = ReadKalibrCamchain(*camchain);
  if (index >= cameras.size()) {
    throw InputError(*camchain, fmt::format("no cam{} entry for {}", index, dir.string()));
  }
  EurocCameraSensor sensor = cameras[index];
  const std::vector<ImageEntry> list = ReadEurocImageList(dir / "data.csv", dir / "data");
  std::vector<std::int64_t> dt;
  for (std::size_t i = 1; i < list.size(); ++i) dt.push_back(list[i].t_ns - list[i - 1].t_ns);
  if (dt.empty()) throw InputError(dir / "data.csv", "fewer than two images: no frame rate");
  std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
  sensor.rate_hz = 1e9 / static_cast<double>(dt[dt.size() / 2]);
  return sensor;
}

// Both lists are strictly increasing: a merge finds exact timestamp matches.
std::vector<StereoPair> MatchStereoPairs(const ImageStream& cam0, const ImageStream& cam1,
                                         const fs::path& name) {
  std::vector<StereoPair> pairs;
  const auto& left = cam0.images;
  const auto& right = cam1.images;
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < left.size() && j < right.size()) {
    if (left[i].t_ns < right[j].t_ns) {
      ++i;
    } else if (right[j].t_ns < left[i].t_ns) {
      ++j;
    } else {
      pairs.push_back({left[i].t_ns, i, j});
      ++i;
      ++j;
    }
  }
  const std::size_t unpaired = left.size() + right.size() - 2 * pairs.size();
  if (unpaired > 0) {
    PKSLAM_LOG_DEBUG("{}: {} usable images have no partner with the same timestamp", name.string(),
                     unpaired);
  }
  return pairs;
}

}  // namespace

EurocDataset EurocDataset::FromImageStreams(const fs::path& root, ImageStream cam0,
                                            std::optional<ImageStream> cam1) {
  EurocDataset d;
  d.mav0_ = root;
  d.cam0_ = std::move(cam0);
  if (cam1 && !cam1->images.empty()) {
    d.cam1_ = std::move(*cam1);
    d.cam1_sensor_ = EurocCameraSensor{};
    d.stereo_pairs_ = MatchStereoPairs(d.cam0_, *d.cam1_, root);
  }
  return d;
}

EurocDataset EurocDataset::Open(const fs::path& root, const EurocOptions& options) {
  options.Check();
  EurocDataset d;
  d.mav0_ = ResolveMav0(root);

  const fs::path cam0_dir = d.mav0_ / "cam0";
  if (!fs::is_regular_file(cam0_dir / "data.csv")) {
    throw InputError(cam0_dir / "data.csv", "file not found (cam0 is required)");
  }
  d.cam0_sensor_ = CameraSensorOf(d.mav0_, cam0_dir, 0);
  d.cam0_ = ReadCameraStream(cam0_dir, "cam0", d.cam0_sensor_, options.frame_gap_periods);

  const fs::path cam1_dir = d.mav0_ / "cam1";
  if (fs::is_directory(cam1_dir)) {
    d.cam1_sensor_ = CameraSensorOf(d.mav0_, cam1_dir, 1);
    d.cam1_ = ReadCameraStream(cam1_dir, "cam1", *d.cam1_sensor_, options.frame_gap_periods);
    d.stereo_pairs_ = MatchStereoPairs(d.cam0_, *d.cam1_, d.mav0_);
  }

  const fs::path imu_dir = d.mav0_ / "imu0";
  if (options.read_imu && fs::is_directory(imu_dir)) {
    const auto kalibr_imu = FindKalibrImu(d.mav0_);
    d.imu_sensor_ = !fs::exists(imu_dir / "sensor.yaml") && kalibr_imu
                        ? ReadKalibrImu(*kalibr_imu)
                        : ReadEurocImuSensor(imu_dir / "sensor.yaml");
    d.imu_ = ReadEurocImu(imu_dir / "data.csv", options.imu_limits);
    std::vector<std::int64_t> t_ns;
    t_ns.reserve(d.imu_.size());
    for (const ImuSample& s : d.imu_) t_ns.push_back(s.t_ns);
    CheckTimeBase(t_ns, d.imu_sensor_->rate_hz, "imu0/sensor.yaml", imu_dir / "data.csv",
                  "IMU samples are");
    d.imu_gaps_ = FindTimeGaps(t_ns, 1e9 / d.imu_sensor_->rate_hz, options.imu_gap_periods);
    if (!d.imu_gaps_.empty()) {
      PKSLAM_LOG_WARN(
          "{}: {} IMU gaps longer than {} periods (first at t = {} ns, {:.1f} "
          "periods)",
          (imu_dir / "data.csv").string(), d.imu_gaps_.size(), options.imu_gap_periods,
          d.imu_gaps_.front().begin_ns, d.imu_gaps_.front().periods);
    }
  }

  const fs::path gt_csv = d.mav0_ / "state_groundtruth_estimate0" / "data.csv";
  if (options.read_ground_truth && fs::is_regular_file(gt_csv)) {
    d.ground_truth_ = ReadEurocGroundTruth(gt_csv);
  }
  return d;
}

const EurocCameraSensor& EurocDataset::cam1_sensor() const {
  PKSLAM_CHECK(cam1_sensor_.has_value(), "dataset {} has no cam1", mav0_.string());
  return *cam1_sensor_;
}

const ImageStream& EurocDataset::cam1() const {
  PKSLAM_CHECK(cam1_.has_value(), "dataset {} has no cam1", mav0_.string());
  return *cam1_;
}

const EurocImuSensor& EurocDataset::imu_sensor() const {
  PKSLAM_CHECK(imu_sensor_.has_value(), "dataset {} has no imu0", mav0_.string());
  return *imu_sensor_;
}

std::vector<ImuSample> EurocDataset::ImuBetween(std::int64_t t0_ns, std::int64_t t1_ns) const {
  const auto after = [](const ImuSample& s, std::int64_t t) { return s.t_ns <= t; };
  const auto begin = std::lower_bound(imu_.begin(), imu_.end(), t0_ns, after);
  const auto end = std::lower_bound(begin, imu_.end(), t1_ns, after);
  return std::vector<ImuSample>(begin, end);
}

cv::Mat EurocDataset::LoadCam0(std::size_t i) const {
  PKSLAM_CHECK(i < cam0_.images.size(), "cam0 index {} of {}", i, cam0_.images.size());
  return LoadGreyImage(cam0_.images[i].path);
}

cv::Mat EurocDataset::LoadCam1(std::size_t i) const {
  const ImageStream& stream = cam1();
  PKSLAM_CHECK(i < stream.images.size(), "cam1 index {} of {}", i, stream.images.size());
  return LoadGreyImage(stream.images[i].path);
}

}  // namespace pkslam
