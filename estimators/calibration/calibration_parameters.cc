// The scalar parameters of a calibration estimate (reports, stats.json) and option checks.
#include <fmt/format.h>

#include <cmath>
#include <utility>

#include "core/util/error.h"
#include "estimators/calibration/calibration_bundle.h"
#include "estimators/calibration/calibration_residuals.h"

namespace pkslam {
namespace {

constexpr double kDeg = 180.0 / M_PI;

void AddCamera(int index, const CameraModel& prior, const CameraModel& estimate, bool free,
               const CalibrationPriorOptions& s, std::vector<CalibrationParameter>* out) {
  const auto p = IntrinsicsBlock(prior);
  const auto e = IntrinsicsBlock(estimate);
  const char* names[kCalibIntrinsicsSize] = {"fx", "fy", "cx", "cy", "k1", "k2"};
  const double sigmas[kCalibIntrinsicsSize] = {s.focal_px,           s.focal_px, s.principal_point_px,
                                               s.principal_point_px, s.k1,       s.k2};
  for (int i = 0; i < kCalibIntrinsicsSize; ++i) {
    // cam1's fy and cy are never estimated (calibration_bundle.h).
    const bool estimated = free && !(index == 1 && (i == 1 || i == 3));
    out->push_back({fmt::format("cam{}.{}", index, names[i]), i < 4 ? "px" : "", p[i], e[i], 0.0,
                    sigmas[i], estimated});
  }
}

// A parent_from_child transform's change from the file, as a user would edit it: the rotation
// vector of R_estimate R_file^T (deg, parent axes), then t_estimate - t_file (mm, parent axes).
void AddExtrinsic(const std::string& prefix, const SE3d& prior, const SE3d& estimate,
                  bool free_rotation, bool free_translation, double sigma_rotation_deg,
                  double sigma_translation_mm, std::vector<CalibrationParameter>* out) {
  const Eigen::Vector3d rotation = (estimate.so3() * prior.so3().Inverse()).Log();
  const Eigen::Vector3d translation = estimate.translation() - prior.translation();
  const char* axes[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    out->push_back({prefix + ".r" + axes[i], "deg", 0.0, rotation[i] * kDeg, 0.0,
                    sigma_rotation_deg, free_rotation});
  }
  for (int i = 0; i < 3; ++i) {
    out->push_back({prefix + ".t" + axes[i], "mm", 0.0, translation[i] * 1e3, 0.0,
                    sigma_translation_mm, free_translation});
  }
}

}  // namespace

void CalibrationPriorOptions::Check() const {
  for (const auto& [name, value] :
       {std::pair{"calibration.prior.focal_px", focal_px},
        std::pair{"calibration.prior.principal_point_px", principal_point_px},
        std::pair{"calibration.prior.k1", k1}, std::pair{"calibration.prior.k2", k2},
        std::pair{"calibration.prior.stereo_rotation_deg", stereo_rotation_deg},
        std::pair{"calibration.prior.stereo_translation_mm", stereo_translation_mm},
        std::pair{"calibration.prior.imu_rotation_deg", imu_rotation_deg},
        std::pair{"calibration.prior.imu_translation_mm", imu_translation_mm},
        std::pair{"calibration.prior.time_offset_ms", time_offset_ms},
        std::pair{"calibration.prior.gyro_scale_pct", gyro_scale_pct},
        std::pair{"calibration.prior.accel_scale_pct", accel_scale_pct},
        std::pair{"calibration.prior.accel_misalignment_deg", accel_misalignment_deg}}) {
    PKSLAM_CHECK_OPTION(value > 0 && std::isfinite(value), name, "{} (a positive sigma)", value);
  }
}

void CalibrationBundleOptions::Check() const {
  PKSLAM_CHECK_OPTION(iterations_first >= 1 && iterations_second >= 0,
                      "calibration_ba.iterations", "{} / {}", iterations_first, iterations_second);
  PKSLAM_CHECK_OPTION(chi2_left > 0 && chi2_right > 0, "calibration_ba.chi2", "{} / {}", chi2_left,
                      chi2_right);
  PKSLAM_CHECK_OPTION(num_threads >= 1, "calibration_ba.num_threads", "{}", num_threads);
  PKSLAM_CHECK_OPTION(min_iterations_before_abort >= 0, "calibration_ba.min_iterations_before_abort",
                      "{}", min_iterations_before_abort);
  PKSLAM_CHECK_OPTION(gravity_magnitude > 0, "calibration_ba.gravity_magnitude", "{}",
                      gravity_magnitude);
  prior.Check();
}

std::vector<CalibrationParameter> CalibrationParameters(const RigCalibration& prior,
                                                        const RigCalibration& estimate,
                                                        const CalibrationFreedom& free,
                                                        const CalibrationPriorOptions& sigmas,
                                                        bool inertial) {
  std::vector<CalibrationParameter> out;
  for (std::size_t c = 0; c < estimate.cameras.size() && c < 2; ++c) {
    AddCamera(static_cast<int>(c), prior.cameras[c], estimate.cameras[c], free.intrinsics[c],
              sigmas, &out);
  }
  if (estimate.stereo()) {
    const std::size_t first = out.size();
    AddExtrinsic("stereo", prior.cam1_from_cam0.Inverse(), estimate.cam1_from_cam0.Inverse(),
                 free.stereo_extrinsic, false, sigmas.stereo_rotation_deg,
                 sigmas.stereo_translation_mm, &out);
    out[first].free = false;  // stereo.rx: held (calibration_bundle.h)
  }
  if (inertial) {
    AddExtrinsic("imu", prior.body_from_cam0, estimate.body_from_cam0, free.imu_rotation,
                 free.imu_translation, sigmas.imu_rotation_deg, sigmas.imu_translation_mm, &out);
    out.push_back({"time_offset", "ms", prior.time_offset_s * 1e3, estimate.time_offset_s * 1e3,
                   0.0, sigmas.time_offset_ms, free.time_offset});
    const char* axes[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; ++i) {
      out.push_back({fmt::format("gyro.s{}", axes[i]), "%", prior.gyro_scale[i] * 100.0,
                     estimate.gyro_scale[i] * 100.0, 0.0, sigmas.gyro_scale_pct,
                     free.gyro_scale});
    }
    // Row-major, as the solve's block (calibration_sigmas.cc relies on the order).
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        if (r == c) {
          out.push_back({fmt::format("accel.s{}", axes[r]), "%", prior.accel_axes(r, c) * 100.0,
                         estimate.accel_axes(r, c) * 100.0, 0.0, sigmas.accel_scale_pct,
                         free.accel_axes && free.accel_scale});
        } else {
          out.push_back({fmt::format("accel.m{}{}", axes[r], axes[c]), "deg",
                         prior.accel_axes(r, c) * kDeg, estimate.accel_axes(r, c) * kDeg, 0.0,
                         sigmas.accel_misalignment_deg, free.accel_axes});
        }
      }
    }
  }
  return out;
}

}  // namespace pkslam
