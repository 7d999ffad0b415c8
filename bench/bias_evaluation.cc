#include "bench/bias_evaluation.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "io/text_rows.h"

namespace pkslam::bench {
namespace {

struct KeyFrameBias {
  std::int64_t t_ns = 0;
  Eigen::Vector3d gyro;
  Eigen::Vector3d accel;
  bool initialised = false;
};

// keyframes_imu.csv: time,vx,vy,vz,bgx,bgy,bgz,bax,bay,baz,valid,map_imu_initialized (time in
// decimal seconds, read exactly to nanoseconds).
std::vector<KeyFrameBias> ReadKeyFrameBiases(const std::filesystem::path& file) {
  std::vector<KeyFrameBias> out;
  ForEachDataRow(file, FieldSeparator::kComma, [&](const TextRow& row) {
    if (row.line == 1 && !row.fields.empty() && row.fields[0] == "time") return;  // header
    RequireFieldCount(row, 12, file, "keyframes_imu.csv (time,vx,...,map_imu_initialized)");
    KeyFrameBias k;
    k.t_ns = SecondsFieldToNs(row.fields[0], file, row.line, "time");
    for (int i = 0; i < 3; ++i) {
      const auto g = static_cast<std::size_t>(4 + i);
      const auto a = static_cast<std::size_t>(7 + i);
      k.gyro[i] = DoubleField(row.fields[g], file, row.line, "gyro bias");
      k.accel[i] = DoubleField(row.fields[a], file, row.line, "accel bias");
    }
    k.initialised = row.fields[10] == "1" && row.fields[11] == "1";
    out.push_back(k);
  });
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
