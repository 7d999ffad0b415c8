#include "evaluation/rpe.h"

#include <fmt/format.h>

#include <cmath>
#include <optional>

#include "core/util/error.h"

namespace pkslam {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

std::vector<PosePairIndices> FramePairs(std::size_t n, std::size_t delta, bool all_pairs) {
  std::vector<PosePairIndices> pairs;
  if (all_pairs) {
    for (std::size_t i = 0; i + delta < n; ++i) pairs.emplace_back(i, i + delta);
  } else {
    for (std::size_t i = 0; i + delta < n; i += delta) pairs.emplace_back(i, i + delta);
  }
  return pairs;
}

// cumulative[k] = path length from pose 0 to pose k.
std::vector<double> CumulativePath(const std::vector<Eigen::Vector3d>& positions) {
  std::vector<double> cumulative(positions.size(), 0.0);
  for (std::size_t k = 1; k < positions.size(); ++k) {
    cumulative[k] = cumulative[k - 1] + (positions[k] - positions[k - 1]).norm();
  }
  return cumulative;
}

// evo's bounded binary search for the end of a `target`-metre stretch starting at `start`:
// bisect on the (non-decreasing) path length; once a value inside [lower, upper] is hit, step
// towards a neighbour that is at least as close (left, ties included) or strictly closer
// (right); stop when neither is. Indices outside [0, n) evaluate like evo's slicing does.
std::optional<std::size_t> PathSearch(const std::vector<double>& cumulative, std::size_t start,
                                      double target, double lower, double upper) {
  const long n = static_cast<long>(cumulative.size());
  const long first = static_cast<long>(start);
  const auto path_to = [&](long x) {
    if (x <= first) return 0.0;
    return cumulative[static_cast<std::size_t>(std::min(x, n - 1))] - cumulative[start];
  };
  long lo = 0;
  long hi = n - 1;
  while (lo <= hi) {
    const long mid = (lo + hi) / 2;
    const double value = path_to(mid);
    if (lower <= value && value <= upper) {
      const double residual = std::abs(value - target);
      if (std::abs(path_to(mid - 1) - target) <= residual) {
        hi = mid - 1;
        continue;
      }
      if (std::abs(path_to(mid + 1) - target) < residual) {
        lo = mid + 1;
        continue;
      }
      return static_cast<std::size_t>(mid);
    }
    if (target < value) {
      hi = mid - 1;
    } else {
      lo = mid + 1;
    }
  }
  return std::nullopt;
}

std::vector<PosePairIndices> MeterPairs(const std::vector<Eigen::Vector3d>& positions,
                                        const RpeOptions& options) {
  std::vector<PosePairIndices> pairs;
  if (positions.empty()) return pairs;
  if (options.all_pairs) {
    const std::vector<double> cumulative = CumulativePath(positions);
    const double tolerance = options.delta * options.relative_tolerance;
    for (std::size_t i = 0; i < positions.size(); ++i) {
      if (const auto j = PathSearch(cumulative, i, options.delta, options.delta - tolerance,
                                    options.delta + tolerance)) {
        pairs.emplace_back(i, *j);
      }
    }
    return pairs;
  }
  std::vector<std::size_t> kept;
  double path = 0.0;
  for (std::size_t k = 1; k < positions.size(); ++k) {
    path += (positions[k] - positions[k - 1]).norm();
    if (path >= options.delta) {
      kept.push_back(k);
      path = 0.0;
    }
  }
  for (std::size_t k = 1; k < kept.size(); ++k) pairs.emplace_back(kept[k - 1], kept[k]);
  return pairs;
}

}  // namespace

RpeUnit ParseRpeUnit(std::string_view name) {
  if (name == "frames") return RpeUnit::kFrames;
  if (name == "m" || name == "meters" || name == "metres") return RpeUnit::kMeters;
  throw OptionError(fmt::format("unknown RPE unit '{}' (expected frames|m)", name));
}

std::string_view RpeUnitName(RpeUnit unit) { return unit == RpeUnit::kFrames ? "frames" : "m"; }

void RpeOptions::Check() const {
  PKSLAM_CHECK_OPTION(std::isfinite(delta) && delta > 0.0, "rpe delta", "{}", delta);
  if (unit == RpeUnit::kFrames) {
    PKSLAM_CHECK_OPTION(delta == std::floor(delta) && delta < 1e9, "rpe delta",
                        "{} is not a whole number of frames", delta);
  }
  PKSLAM_CHECK_OPTION(
      std::isfinite(relative_tolerance) && relative_tolerance >= 0.0 && relative_tolerance < 1.0,
      "rpe relative_tolerance", "{}", relative_tolerance);
}

std::vector<PosePairIndices> SelectRpePairs(const std::vector<Eigen::Vector3d>& positions,
                                            const RpeOptions& options) {
  options.Check();
  if (options.unit == RpeUnit::kFrames) {
    return FramePairs(positions.size(), static_cast<std::size_t>(options.delta), options.all_pairs);
  }
  return MeterPairs(positions, options);
}

RpeResult ComputeRpe(const std::vector<SE3d>& ref, const std::vector<SE3d>& est,
                     const RpeOptions& options) {
  PKSLAM_CHECK(ref.size() == est.size(), "RPE needs associated poses ({} vs {})", ref.size(),
               est.size());
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(est.size());
  for (const SE3d& pose : est) positions.push_back(pose.translation());

  RpeResult result;
  result.pairs = SelectRpePairs(positions, options);
  if (result.pairs.empty()) {
    const std::string rule = options.unit == RpeUnit::kFrames
                                 ? std::string("the trajectory is too short")
                                 : fmt::format("no stretch of path is within {}% of it",
                                               100.0 * options.relative_tolerance);
    throw OptionError(
        fmt::format("RPE delta {} {} selects no pose pair among {} associated poses ({} "
                    "pairs): {}; choose another delta",
                    options.delta, RpeUnitName(options.unit), est.size(),
                    options.all_pairs ? "all" : "consecutive", rule));
  }
  for (const auto& [i, j] : result.pairs) {
    const SE3d ref_motion = ref[i].Inverse() * ref[j];
    const SE3d est_motion = est[i].Inverse() * est[j];
    const SE3d error = ref_motion.Inverse() * est_motion;
    result.translation_errors_m.push_back(error.translation().norm());
    result.rotation_errors_deg.push_back(error.so3().Angle() * kRadToDeg);
  }
  result.translation_m = ComputeErrorStatistics(result.translation_errors_m);
  result.rotation_deg = ComputeErrorStatistics(result.rotation_errors_deg);
  return result;
}

}  // namespace pkslam
