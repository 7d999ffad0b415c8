#include "mapping/calibration_refinement.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

#include "core/util/error.h"

namespace pkslam {
namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

void OnlineCalibrationOptions::Check() const {
  prior.Check();
  PKSLAM_CHECK_OPTION(max_observations_per_keyframe >= 0,
                      "calibration.max_observations_per_keyframe", "{}",
                      max_observations_per_keyframe);
  PKSLAM_CHECK_OPTION(iterations_first >= 1 && iterations_second >= 0, "calibration.iterations",
                      "{} / {}", iterations_first, iterations_second);
  PKSLAM_CHECK_OPTION(final_max_observations_per_keyframe >= 0 && final_iterations_first >= 1 &&
                          final_iterations_second >= 0,
                      "calibration.final", "{} observations, {} / {} iterations",
                      final_max_observations_per_keyframe, final_iterations_first,
                      final_iterations_second);
  PKSLAM_CHECK_OPTION(min_iterations >= 0, "calibration.min_iterations", "{}", min_iterations);
  PKSLAM_CHECK_OPTION(first_after_s > 0, "calibration.first_after_s", "{}", first_after_s);
  PKSLAM_CHECK_OPTION(growth > 1, "calibration.growth", "{} (> 1)", growth);
  PKSLAM_CHECK_OPTION(min_keyframes >= 2, "calibration.min_keyframes", "{}", min_keyframes);
  PKSLAM_CHECK_OPTION(min_rotation_rate >= 0 && min_lever_rotation_rate >= 0 &&
                          min_turn_rate >= 0 && min_speed >= 0,
                      "calibration gates", "rates must not be negative");
  PKSLAM_CHECK_OPTION(min_covered_cells >= 0 && min_covered_cells <= 16,
                      "calibration.min_covered_cells", "{} (of 16)", min_covered_cells);
  PKSLAM_CHECK_OPTION(min_cell_observations >= 0 && min_stereo_observations >= 0,
                      "calibration gates", "counts must not be negative");
  PKSLAM_CHECK_OPTION(max_prior_sigmas > 0 && max_step_prior_sigmas > 0 &&
                          final_max_step_prior_sigmas > 0,
                      "calibration.max_prior_sigmas", "{} / {} / {}", max_prior_sigmas,
                      max_step_prior_sigmas, final_max_step_prior_sigmas);
}

CalibrationGates DecideFreedom(const CalibrationBundleProblem& problem, Sensor sensor,
                               const OnlineCalibrationOptions& options) {
  CalibrationGates g;
  // The groups only an initialised IMU can free; a group added here is frozen with the rest.
  constexpr std::array<const char*, 6> kInertialGroups = {
      "imu_rotation", "imu_translation", "time_offset", "gyro_scale", "accel_axes", "accel_scale"};
  const auto freeze_all = [&](const std::string& reason) {
    g.frozen["intrinsics"] = reason;
    g.frozen["stereo"] = reason;
    for (const char* group : kInertialGroups) g.frozen[group] = reason;
    g.free = {};
  };
  if (IsRgbd(sensor)) {
    freeze_all("RGB-D: the depth image's registration is taken as given");
    return g;
  }
  if (IsMonocular(sensor) && !IsInertial(sensor)) {
    freeze_all("monocular without IMU: no metric scale to hold the intrinsics against");
    return g;
  }
  const BundleProblem& visual = problem.bundle.visual;
  const int num_kf = static_cast<int>(visual.keyframes.size());
  if (num_kf < options.min_keyframes) {
    freeze_all(fmt::format("{} keyframes (at least {})", num_kf, options.min_keyframes));
    return g;
  }

  // Coverage of the image and stereo matches.
  constexpr int kCells = 4;
  std::array<int, kCells * kCells> cells{};
  const CameraModel& cam0 = problem.initial.cameras.front();
  for (std::size_t i = 0; i < problem.raw.size(); ++i) {
    const Eigen::Vector2d& uv = problem.raw[i].left;
    const int cx = std::clamp(static_cast<int>(uv.x() / cam0.width() * kCells), 0, kCells - 1);
    const int cy = std::clamp(static_cast<int>(uv.y() / cam0.height() * kCells), 0, kCells - 1);
    ++cells[static_cast<std::size_t>(cy * kCells + cx)];
    g.stereo_observations += problem.raw[i].has_right ? 1 : 0;
  }
  for (int c : cells) g.covered_cells += c >= options.min_cell_observations ? 1 : 0;
  const bool stereo = IsStereo(sensor) && problem.initial.stereo();
  if (IsMonocular(sensor) && !options.monocular_intrinsics) {
    g.frozen["intrinsics"] =
        "held at the file's values for a monocular rig (the focal length trades against depth)";
  } else if (g.covered_cells >= options.min_covered_cells) {
    g.free.intrinsics = {true, stereo};
  } else {
    g.frozen["intrinsics"] = fmt::format("observations cover {} of 16 image cells (at least {})",
                                         g.covered_cells, options.min_covered_cells);
  }
  if (stereo) {
    if (g.stereo_observations >= options.min_stereo_observations) {
      g.free.stereo_extrinsic = true;
    } else {
      g.frozen["stereo"] = fmt::format("{} stereo matches (at least {})", g.stereo_observations,
                                       options.min_stereo_observations);
    }
  }

  if (!IsInertial(sensor) || !problem.inertial) {
    if (IsInertial(sensor)) {
      for (const char* group : kInertialGroups)
        g.frozen[group] = "the map's IMU is not initialised";
    }
    return g;
  }
  // Motion: angular rates and speeds at the keyframes of the chain.
  std::vector<double> rates;
  std::vector<double> speeds;
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  int n = 0;
  for (int i = 0; i < num_kf; ++i) {
    if (i >= static_cast<int>(problem.bundle.inertial.size()) || problem.bundle.inertial[i] == 0) {
      continue;
    }
    const Eigen::Vector3d& w = problem.angular_velocity[static_cast<std::size_t>(i)];
    m += w * w.transpose();
    rates.push_back(w.norm());
    speeds.push_back(problem.bundle.velocities[static_cast<std::size_t>(i)].norm());
    ++n;
  }
  if (n > 0) m /= n;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(m);
  g.second_axis_rate = std::sqrt(std::max(0.0, eigen.eigenvalues()[1]));  // ascending order
  g.median_turn_rate = Median(rates);
  g.median_speed = Median(speeds);
  if (g.second_axis_rate >= options.min_rotation_rate) {
    g.free.imu_rotation = true;
  } else {
    g.frozen["imu_rotation"] =
        fmt::format("rotation about one axis only (second axis {:.3f} rad/s, at least {})",
                    g.second_axis_rate, options.min_rotation_rate);
  }
  // The gyro's scale factors need the same turning: about an axis the body never turned, the
  // prior holds that axis's factor at the file's value.
  if (!options.gyro_scale) {
    g.frozen["gyro_scale"] = "held at the file's value (--calibrate-hold-gyro-scale)";
  } else if (g.second_axis_rate >= options.min_rotation_rate) {
    g.free.gyro_scale = true;
  } else {
    g.frozen["gyro_scale"] = g.frozen["imu_rotation"];
  }
  // The accelerometer's axes: gravity must be seen along more than one axis, which the same
  // turning gives (a body that never tilts sees gravity along one axis only).
  if (!options.accel_axes) {
    g.frozen["accel_axes"] = "held at the file's value (--calibrate-hold-accel-axes)";
  } else if (IsMonocular(sensor) && !options.monocular_accel_axes) {
    g.frozen["accel_axes"] =
        "held at the file's value for a monocular rig (it trades against the map's scale; "
        "--calibrate-mono-accel-axes estimates it)";
  } else if (g.second_axis_rate >= options.min_rotation_rate) {
    g.free.accel_axes = true;
  } else {
    g.frozen["accel_axes"] = g.frozen["imu_rotation"];
  }
  if (!g.free.accel_axes) {
    g.frozen["accel_scale"] = g.frozen["accel_axes"];
  } else if (!options.accel_scale) {
    g.frozen["accel_scale"] = "held at the file's value (--calibrate-accel-scale estimates it)";
  } else {
    g.free.accel_scale = true;
  }
  if (!options.imu_translation) {
    g.frozen["imu_translation"] = "held at the file's value (--calibrate-lever-arm estimates it)";
  } else if (g.second_axis_rate >= options.min_lever_rotation_rate) {
    g.free.imu_translation = true;
  } else {
    g.frozen["imu_translation"] =
        fmt::format("too little rotation to see the lever arm (second axis {:.3f} rad/s, at "
                    "least {})",
                    g.second_axis_rate, options.min_lever_rotation_rate);
  }
  if (g.median_turn_rate >= options.min_turn_rate || g.median_speed >= options.min_speed) {
    g.free.time_offset = true;
  } else {
    g.frozen["time_offset"] =
        fmt::format("the images barely move (median {:.3f} rad/s, {:.3f} m/s)",
                    g.median_turn_rate, g.median_speed);
  }
  return g;
}

std::optional<std::string> ImplausibleEstimate(const CalibrationBundleProblem& problem,
                                               const RigCalibration& estimate,
                                               const OnlineCalibrationOptions& options,
                                               double max_step_prior_sigmas) {
  const auto check = [&](const RigCalibration& from, double limit,
                         const char* what) -> std::optional<std::string> {
    for (const CalibrationParameter& p :
         CalibrationParameters(from, estimate, problem.free, options.prior, problem.inertial)) {
      if (!p.free) continue;
      const double n = std::abs(p.estimate - p.file) / p.prior_sigma;
      if (n > limit) {
        return fmt::format("{} would move {:.3g} {} {} ({:.0f} prior sigmas, at most {:.0f})",
                           p.name, p.estimate - p.file, p.unit, what, n, limit);
      }
    }
    return std::nullopt;
  };
  if (auto why = check(problem.prior, options.max_prior_sigmas, "from the file")) return why;
  return check(problem.initial, max_step_prior_sigmas, "in one adjustment");
}

}  // namespace pkslam
