#include "evaluation/segment_error.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"

namespace pkslam {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// The first index in [from, end) whose accumulated length equals accumulated[k] (lengths do not
// decrease, so repeated values are a run ending at k).
std::size_t FirstWithSameLength(const std::vector<double>& accumulated, std::size_t from,
                                std::size_t k) {
  while (k > from && accumulated[k - 1] == accumulated[k]) --k;
  return k;
}

// |yaw| and the gravity (roll, pitch) part of a world-frame rotation R = Rz(yaw) Ry(pitch)
// Rx(roll), in degrees.
std::pair<double, double> YawAndGravityDeg(const Eigen::Matrix3d& r) {
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  const double pitch = std::atan2(-r(2, 0), std::hypot(r(0, 0), r(1, 0)));
  const double roll = std::atan2(r(2, 1), r(2, 2));
  return {std::abs(yaw) * kRadToDeg, std::hypot(pitch, roll) * kRadToDeg};
}

}  // namespace

void SegmentErrorOptions::Check() const {
  for (const double length : lengths_m) {
    if (!(length > 0.0) || !std::isfinite(length)) {
      throw OptionError(fmt::format("segment length {} m: must be a positive number", length));
    }
  }
  if (lengths_m.empty() && fractions.empty()) {
    throw OptionError("segment errors need lengths or fractions of the path");
  }
  for (const double f : fractions) {
    if (!(f > 0.0 && f <= 1.0)) {
      throw OptionError(fmt::format("segment fraction {}: must be in (0, 1]", f));
    }
  }
  if (!(reference_path_m >= 0.0) || !std::isfinite(reference_path_m)) {
    throw OptionError(fmt::format("segment reference path {} m: must be >= 0", reference_path_m));
  }
  if (!(max_length_difference > 0.0 && max_length_difference < 1.0)) {
    throw OptionError(
        fmt::format("segment max length difference {}: must be in (0, 1)", max_length_difference));
  }
}

std::vector<double> AccumulatedPathLength(const std::vector<Eigen::Vector3d>& positions) {
  std::vector<double> accumulated;
  accumulated.reserve(positions.size());
  double sum = 0.0;
  for (std::size_t k = 0; k < positions.size(); ++k) {
    if (k > 0) sum += (positions[k] - positions[k - 1]).norm();
    accumulated.push_back(sum);
  }
  return accumulated;
}

std::vector<double> DefaultSegmentLengths(double path_length_m,
                                          const std::vector<double>& fractions) {
  std::vector<double> lengths;
  for (const double f : fractions) lengths.push_back(std::trunc(f * path_length_m * 100.0) / 100.0);
  return lengths;
}

std::vector<PosePairIndices> SelectSegmentPairs(const std::vector<double>& accumulated_m,
                                                double length_m, double max_length_difference) {
  std::vector<PosePairIndices> pairs;
  const double tolerance = max_length_difference * length_m;
  const auto begin = accumulated_m.begin();
  for (std::size_t i = 0; i < accumulated_m.size(); ++i) {
    const double target = accumulated_m[i] + length_m;
    // The nearest lengths to the target are the first at or above it and the last below it.
    const std::size_t above = static_cast<std::size_t>(
        std::lower_bound(begin + static_cast<std::ptrdiff_t>(i), accumulated_m.end(), target) -
        begin);
    std::size_t best = accumulated_m.size();
    double best_error = tolerance;
    if (above > i) {
      const std::size_t below = FirstWithSameLength(accumulated_m, i, above - 1);
      const double error = std::abs(accumulated_m[below] - target);
      if (error < best_error) {
        best = below;
        best_error = error;
      }
    }
    if (above < accumulated_m.size()) {
      const double error = std::abs(accumulated_m[above] - target);
      if (error < best_error) best = above;  // on a tie the earlier (below) one stays
    }
    if (best < accumulated_m.size()) pairs.emplace_back(i, best);
  }
  return pairs;
}

std::vector<SegmentErrors> ComputeSegmentErrors(const std::vector<SE3d>& ref,
                                                const std::vector<SE3d>& est,
                                                const SegmentErrorOptions& options) {
  options.Check();
  PKSLAM_CHECK(ref.size() == est.size(), "segment errors need associated poses ({} vs {})",
               ref.size(), est.size());
  std::vector<Eigen::Vector3d> ref_positions;
  ref_positions.reserve(ref.size());
  for (const SE3d& pose : ref) ref_positions.push_back(pose.translation());
  const std::vector<double> accumulated = AccumulatedPathLength(ref_positions);
  const double path_m = options.reference_path_m > 0.0 ? options.reference_path_m
                        : accumulated.empty()          ? 0.0
                                                       : accumulated.back();
  const std::vector<double> lengths = options.lengths_m.empty()
                                          ? DefaultSegmentLengths(path_m, options.fractions)
                                          : options.lengths_m;

  std::vector<SegmentErrors> all;
  for (const double length : lengths) {
    SegmentErrors segment;
    segment.length_m = length;
    if (length > 0.0) {
      segment.pairs = SelectSegmentPairs(accumulated, length, options.max_length_difference);
    }
    for (const auto& [i, j] : segment.pairs) {
      const SE3d error = (ref[i].Inverse() * ref[j]).Inverse() * (est[i].Inverse() * est[j]);
      const double translation = error.translation().norm();
      const double rotation = error.so3().Angle() * kRadToDeg;
      const Eigen::Matrix3d r_j = est[j].so3().Matrix();
      const auto [yaw, gravity] = YawAndGravityDeg(r_j * error.so3().Matrix() * r_j.transpose());
      segment.translation_m.push_back(translation);
      segment.translation_percent.push_back(100.0 * translation / length);
      segment.rotation_deg.push_back(rotation);
      segment.rotation_deg_per_m.push_back(rotation / length);
      segment.yaw_deg.push_back(yaw);
      segment.gravity_deg.push_back(gravity);
    }
    if (!segment.empty()) {
      segment.translation_m_stats = ComputeErrorStatistics(segment.translation_m);
      segment.translation_percent_stats = ComputeErrorStatistics(segment.translation_percent);
      segment.rotation_deg_stats = ComputeErrorStatistics(segment.rotation_deg);
    }
    all.push_back(std::move(segment));
  }
  return all;
}

}  // namespace pkslam
