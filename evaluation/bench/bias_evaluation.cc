#include "evaluation/bench/bias_evaluation.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/util/error.h"

namespace pkslam::bench {
namespace {

struct KeyFrameBias {
  std::int64_t t_ns = 0;
  Eigen::Vector3d gyro;
  Eigen::Vector3d accel;
  bool initialised = false;
};

// keyframes_imu.csv: time,vx,vy,vz,bgx,bgy,bgz,bax,bay,baz,valid,map_imu_initialized (time in
// seconds with nanosecond digits).
std::vector<KeyFrameBias> ReadKeyFrameBiases(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file, "cannot read");
  std::string line;
  if (!std::getline(in, line) || line.rfind("time,", 0) != 0) {
    throw InputError(file, 1, "expected the header 'time,vx,vy,vz,bgx,...'");
  }
  std::vector<KeyFrameBias> out;
  std::size_t n = 1;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty()) continue;
    std::vector<std::string> f;
    std::stringstream ss(line);
    std::string field;
    while (std::getline(ss, field, ',')) f.push_back(field);
    if (f.size() != 12) throw InputError(file, n, fmt::format("{} fields, expected 12", f.size()));
    KeyFrameBias k;
    try {
      // Seconds.nanoseconds: split to keep the nanosecond timestamp exact.
      const std::size_t dot = f[0].find('.');
      const std::string sec = f[0].substr(0, dot);
      std::string frac = dot == std::string::npos ? "" : f[0].substr(dot + 1);
      frac.resize(9, '0');
      k.t_ns = std::stoll(sec) * 1000000000LL + std::stoll(frac);
      for (int i = 0; i < 3; ++i) {
        k.gyro[i] = std::stod(f[4 + static_cast<std::size_t>(i)]);
        k.accel[i] = std::stod(f[7 + static_cast<std::size_t>(i)]);
      }
      k.initialised = f[10] == "1" && f[11] == "1";
    } catch (const std::exception&) {
      throw InputError(file, n, "not a number in '" + line + "'");
    }
    out.push_back(k);
  }
  return out;
}

}  // namespace

std::optional<BiasErrors> EvaluateBiases(const std::filesystem::path& keyframes_imu_csv,
                                         const Trajectory& gt, double after_s) {
  if (!std::filesystem::exists(keyframes_imu_csv) || !gt.has_extras() || gt.empty()) {
    return std::nullopt;
  }
  const auto keyframes = ReadKeyFrameBiases(keyframes_imu_csv);
  if (keyframes.empty()) return std::nullopt;
  std::int64_t first = keyframes.front().t_ns;
  for (const auto& k : keyframes) first = std::min(first, k.t_ns);
  const auto after_ns = static_cast<std::int64_t>(after_s * 1e9);
  const std::vector<std::int64_t> times = gt.Timestamps();
  BiasErrors e;
  for (const auto& k : keyframes) {
    if (!k.initialised || k.t_ns - first < after_ns) continue;
    const auto it = std::lower_bound(times.begin(), times.end(), k.t_ns);
    std::size_t i = static_cast<std::size_t>(it - times.begin());
    if (i == times.size() || (i > 0 && k.t_ns - times[i - 1] < times[i] - k.t_ns)) --i;
    if (std::llabs(times[i] - k.t_ns) > 50000000LL) continue;
    const GroundTruthExtras& truth = gt.extras[i];
    if (truth.gyro_bias.norm() <= 0.0 || truth.accel_bias.norm() <= 0.0) continue;
    e.gyro_pct += 100.0 * (k.gyro - truth.gyro_bias).norm() / truth.gyro_bias.norm();
    e.accel_pct += 100.0 * (k.accel - truth.accel_bias).norm() / truth.accel_bias.norm();
    ++e.keyframes;
  }
  if (e.keyframes == 0) return std::nullopt;
  e.gyro_pct /= e.keyframes;
  e.accel_pct /= e.keyframes;
  return e;
}

}  // namespace pkslam::bench
