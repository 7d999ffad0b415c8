#include "rgbd/icp.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "core/util/error.h"
#include "rgbd/rigid_alignment.h"

namespace pkslam::rgbd {

void IcpOptions::Check() const {
  PKSLAM_CHECK_OPTION(max_iterations >= 1, "icp.max_iterations", "{}", max_iterations);
  PKSLAM_CHECK_OPTION(min_update_translation_m >= 0, "icp.min_update_translation_m", "{}",
                      min_update_translation_m);
  PKSLAM_CHECK_OPTION(min_update_rotation_rad >= 0, "icp.min_update_rotation_rad", "{}",
                      min_update_rotation_rad);
  PKSLAM_CHECK_OPTION(min_relative_mse_decrease >= 0, "icp.min_relative_mse_decrease", "{}",
                      min_relative_mse_decrease);
  PKSLAM_CHECK_OPTION(max_correspondence_m >= 0, "icp.max_correspondence_m", "{}",
                      max_correspondence_m);
}

namespace {

// Besl-McKay's extrapolation: the step to take along the last update direction, or 0.
// history: the last three estimates (tangent vectors, oldest first) and their residual MSEs.
double ExtrapolationStep(const std::array<Eigen::Matrix<double, 6, 1>, 3>& q,
                         const std::array<double, 3>& d) {
  constexpr double kMaxAngleRad = 10.0 * M_PI / 180.0;
  const Eigen::Matrix<double, 6, 1> step_new = q[2] - q[1];
  const Eigen::Matrix<double, 6, 1> step_old = q[1] - q[0];
  const double len_new = step_new.norm(), len_old = step_old.norm();
  if (len_new < 1e-12 || len_old < 1e-12) return 0;
  const double cos_angle = step_new.dot(step_old) / (len_new * len_old);
  if (cos_angle < std::cos(kMaxAngleRad)) return 0;
  // Error as a function of the distance along the line: points at x = -(len_new + len_old),
  // -len_new and 0.
  const double x0 = -(len_new + len_old), x1 = -len_new, x2 = 0;
  // Parabola d = a x^2 + b x + c through the three points (divided differences).
  const double f01 = (d[1] - d[0]) / (x1 - x0), f12 = (d[2] - d[1]) / (x2 - x1);
  const double a = (f12 - f01) / (x2 - x0);
  const double b = f12 - a * (x1 + x2);
  // Least-squares line through the three points.
  const double mx = (x0 + x1 + x2) / 3, md = (d[0] + d[1] + d[2]) / 3;
  const double sxx = (x0 - mx) * (x0 - mx) + (x1 - mx) * (x1 - mx) + (x2 - mx) * (x2 - mx);
  const double sxd = (x0 - mx) * (d[0] - md) + (x1 - mx) * (d[1] - md) + (x2 - mx) * (d[2] - md);
  const double slope = sxd / sxx, intercept = md - slope * mx;
  const double v_max = 25 * len_new;
  const double v_parabola = a > 0 ? -b / (2 * a) : -1;
  const double v_line = slope < 0 ? -intercept / slope : -1;
  if (v_parabola > 0) return std::min(v_parabola, v_max);
  if (v_line > 0) return std::min(v_line, v_max);
  return 0;
}

}  // namespace

IcpResult IcpPointToPoint(const std::vector<Eigen::Vector3f>& source, const PointCloudIndex& target,
                          const SE3d& initial_target_from_source, const IcpOptions& options) {
  options.Check();
  IcpResult result;
  result.target_from_source = initial_target_from_source;
  if (source.size() < 3 || target.size() < 3) return result;
  const float max_d2 =
      options.max_correspondence_m > 0
          ? static_cast<float>(options.max_correspondence_m * options.max_correspondence_m)
          : std::numeric_limits<float>::infinity();
  const auto& target_points = target.points();
  double previous_mse = std::numeric_limits<double>::infinity();
  SE3d estimate = initial_target_from_source;
  // Acceleration history: the last solutions (tangent) and their least-squares residual MSEs.
  std::array<Eigen::Matrix<double, 6, 1>, 3> history_q;
  std::array<double, 3> history_d{};
  int history = 0;
  for (int iteration = 1; iteration <= options.max_iterations; ++iteration) {
    result.iterations = iteration;
    const Eigen::Matrix3f r = estimate.RotationMatrix().cast<float>();
    const Eigen::Vector3f t = estimate.translation().cast<float>();
    RigidAlignmentAccumulator acc;
    double sum_d2 = 0;
    for (const Eigen::Vector3f& p : source) {
      const Eigen::Vector3f moved = r * p + t;
      const auto [index, d2] = target.Nearest(moved);
      if (index < 0 || d2 > max_d2) continue;
      // Pairs are (original source point, target point): the solution is the full
      // target_from_source, not an increment.
      acc.Add(p.cast<double>(), target_points[index].cast<double>());
      sum_d2 += d2;
    }
    result.correspondences = static_cast<int>(acc.count());
    const auto solved = acc.Solve();
    if (!solved) {
      result.success = false;
      return result;
    }
    const double mse = sum_d2 / static_cast<double>(acc.count());
    result.rmse_m = std::sqrt(mse);
    const SE3d update = *solved * estimate.Inverse();
    estimate = *solved;
    result.success = true;
    result.target_from_source = estimate;
    const bool small_update = update.translation().norm() < options.min_update_translation_m &&
                              update.so3().Angle() < options.min_update_rotation_rad;
    // Stalled: the error decreased, but by less than the tolerance (with pair rejection the
    // error can also rise while the pairs change; that is not convergence).
    const double decrease = previous_mse - mse;
    const bool stalled =
        decrease >= 0 && decrease < options.min_relative_mse_decrease * previous_mse;
    if (small_update || (std::isfinite(previous_mse) && stalled)) {
      result.converged = true;
      break;
    }
    previous_mse = mse;
    if (options.accelerate && iteration < options.max_iterations) {
      if (history == 3) {
        std::rotate(history_q.begin(), history_q.begin() + 1, history_q.end());
        std::rotate(history_d.begin(), history_d.begin() + 1, history_d.end());
        history = 2;
      }
      history_q[history] = estimate.Log();
      history_d[history] = acc.SumSquaredResiduals(estimate) / static_cast<double>(acc.count());
      ++history;
      if (history == 3) {
        const double v = ExtrapolationStep(history_q, history_d);
        if (v > 0) {
          const Eigen::Matrix<double, 6, 1> direction = (history_q[2] - history_q[1]).normalized();
          estimate = SE3d::Exp(history_q[2] + v * direction);
          result.target_from_source = estimate;
          ++result.accelerations;
          history = 0;  // three fresh plain steps before the next jump
        }
      }
    }
  }
  return result;
}

}  // namespace pkslam::rgbd
