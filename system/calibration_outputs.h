// What a run reports about its calibration (docs/calibration.md): the stats.json "calibration"
// section (each parameter's file value, estimate, sigma and whether it was freed; why the others
// stayed frozen; every adjustment of the run), one warning line per file value the estimate
// contradicts, and OUT/calibration/ with the estimate as EuRoC sensor.yaml files and an
// ORB-SLAM3 settings file, to feed back to pkslam or to another system.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/util/json_writer.h"
#include "io/settings.h"
#include "mapping/calibration_refinement.h"

namespace pkslam {

struct CalibrationReport {
  bool online = false;
  Sensor sensor = Sensor::kStereo;
  RigCalibration file;
  RigCalibration estimate;
  // The final estimate's parameters (sigmas when covariance_ok) and the gates of the final
  // adjustment (empty without one).
  std::vector<CalibrationParameter> parameters;
  bool covariance_ok = false;
  // The parameters' joint covariance (CalibrationBundleResult::parameter_covariance; empty
  // without one).
  Eigen::MatrixXd parameter_covariance;
  std::map<std::string, std::string> frozen;
  std::vector<CalibrationRefinementStat> history;
  std::string note;  // why the final adjustment was not applied ("" when it was, or off)
  // Where the adjustments while mapping solved: "thread" (beside local mapping) or "step"
  // (inside its keyframe step); "" when off.
  std::string solved_in;
  // Wall time of the final adjustment after the last frame (0 without one): gathering the
  // map, the solve (its covariance included) and moving the map to the estimate. It is the part
  // of online calibration's cost that comes after the data (docs/calibration.md, "Cost").
  struct FinalTiming {
    double collect_ms = 0.0;
    double solve_ms = 0.0;
    double covariance_ms = 0.0;
    double apply_ms = 0.0;
  } final_timing;
};

// Where each parameter group came from, for the warnings: the settings file, or a EuRoC
// dataset's sensor.yaml files.
struct CalibrationSources {
  // gyro: the IMU's own errors, the gyro's scale factors (gyro.*) and the accelerometer's axis
  // errors (accel.*).
  std::string cam0, cam1, imu, time_offset, gyro;
};
CalibrationSources SourcesFromSettingsFile(const std::filesystem::path& settings);
CalibrationSources SourcesFromEurocDataset(const std::filesystem::path& dataset);

// A warning per free parameter whose file value is more than `threshold` sigmas from the
// estimate, with the sigma at least a third of the prior's (the prior's third alone when the
// covariance failed), naming the parameter, the size and the file; one more than 5 prior sigmas
// off says the file is wrong for the rig.
// Stereo rigs get one more line when the disparity bias the file makes (a combination of both
// principal points and the stereo rotation, whose sigma comes from the joint covariance, at
// least 0.04 px) is more than `threshold` sigmas from the estimate's, with the depth error it
// means.
std::vector<std::string> CalibrationWarnings(const CalibrationReport& report,
                                             const CalibrationSources& sources,
                                             double threshold = 3.0);

void WriteCalibrationJson(const CalibrationReport& report,
                          const std::vector<std::string>& warnings, JsonWriter* json);

// OUT/calibration/{cam0,cam1}/sensor.yaml (EuRoC; cam0's with timeshift_cam_imu for inertial
// sensors), for inertial sensors OUT/calibration/imu0/sensor.yaml (with pkslam's
// gyroscope_scale_error and accelerometer_axis_errors) and OUT/calibration/settings.yaml
// (ORB-SLAM3 v1.0, `settings` with the estimate).
void WriteCalibrationFiles(const CalibrationReport& report, const Settings& settings,
                           const std::filesystem::path& out_dir);

}  // namespace pkslam
