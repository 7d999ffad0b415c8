// SimulationOptions: validation, quality names, and the sim.yaml record.
#include <yaml-cpp/yaml.h>

#include <fstream>

#include "core/util/error.h"
#include "sim/simulator.h"

namespace pkslam::sim {

Quality ParseQuality(const std::string& name) {
  if (name == "fast") return Quality::kFast;
  if (name == "default") return Quality::kDefault;
  if (name == "high") return Quality::kHigh;
  throw OptionError("quality must be fast, default or high, got '" + name + "'");
}

std::string QualityName(Quality quality) {
  switch (quality) {
    case Quality::kFast:
      return "fast";
    case Quality::kDefault:
      return "default";
    case Quality::kHigh:
      return "high";
  }
  return "?";
}

void SimulationOptions::Check() const {
  PKSLAM_CHECK_OPTION(bench || !output_dir.empty(), "--out", "an output directory is required");
  PKSLAM_CHECK_OPTION(start_s >= 0.0, "--start", "{}", start_s);
  PKSLAM_CHECK_OPTION(duration_s >= 0.0, "--duration", "{}", duration_s);
  PKSLAM_CHECK_OPTION(trajectory.empty() || duration_s == 0.0 || duration_s >= 0.1, "--duration",
                      "replay windows must be >= 0.1 s, got {}", duration_s);
  PKSLAM_CHECK_OPTION(
      camera == "euroc" || camera == "kitti" || camera == "vga" || camera == "tumvi", "camera",
      "'{}' (euroc|kitti|vga|tumvi)", camera);
  PKSLAM_CHECK_OPTION(!(rgbd && camera != "euroc"), "camera",
                      "'{}' with --rgbd (its camera is "
                      "TUM's 640x480 Kinect)",
                      camera);
  PKSLAM_CHECK_OPTION(camera_rate_hz > 0.0 && camera_rate_hz <= imu.rate_hz, "camera_rate_hz", "{}",
                      camera_rate_hz);
  const auto cam_period = static_cast<std::int64_t>(std::llround(1e9 / camera_rate_hz));
  PKSLAM_CHECK_OPTION(cam_period % imu.period_ns() == 0, "camera_rate_hz",
                      "camera period {} ns must be a multiple of the IMU period {} ns (EuRoC "
                      "images share IMU timestamps)",
                      cam_period, imu.period_ns());
  PKSLAM_CHECK_OPTION(
      motion_blur_exposure_s >= 0.0 && motion_blur_exposure_s < 1.0 / camera_rate_hz,
      "--motion-blur", "exposure {} s must be shorter than a frame", motion_blur_exposure_s);
  PKSLAM_CHECK_OPTION(motion_blur_samples >= 0 && motion_blur_samples <= 64, "motion_blur_samples",
                      "{}", motion_blur_samples);
  PKSLAM_CHECK_OPTION(rgbd_rate_hz > 0.0 && rgbd_rate_hz <= 100.0, "rgbd_rate_hz", "{}",
                      rgbd_rate_hz);
  PKSLAM_CHECK_OPTION(depth_noise >= 0.0 && depth_noise <= 10.0, "--depth-noise", "{}",
                      depth_noise);
  PKSLAM_CHECK_OPTION(blackout_begin_s < 0.0 || blackout_end_s >= blackout_begin_s, "--blackout",
                      "end {} before begin {}", blackout_end_s, blackout_begin_s);
  PKSLAM_CHECK_OPTION(cloud_spacing_m >= 0.001 && cloud_spacing_m <= 1.0, "--cloud-spacing", "{}",
                      cloud_spacing_m);
  PKSLAM_CHECK_OPTION(visibility_cell_m >= cloud_spacing_m && visibility_cell_m <= 2.0,
                      "visibility_cell_m", "{} (>= cloud spacing)", visibility_cell_m);
  PKSLAM_CHECK_OPTION(observed_range_m >= 0.0 && observed_range_m <= 100.0, "--observed-range",
                      "{}", observed_range_m);
  PKSLAM_CHECK_OPTION(observed_cell_m >= 0.001 && observed_cell_m <= 2.0, "--observed-cell", "{}",
                      observed_cell_m);
  PKSLAM_CHECK_OPTION(!reference_only || (write_cloud && write_images && !bench),
                      "--reference-only", "{}", "needs images and the cloud (no --bench)");
  PKSLAM_CHECK_OPTION(bench_frames >= 0, "bench_frames", "{}", bench_frames);
  PKSLAM_CHECK_OPTION(landmark_tracks >= 0 && (landmark_tracks == 0 || !rgbd), "--tracks",
                      "{} (EuRoC output only)", landmark_tracks);
  PKSLAM_CHECK_OPTION(cam1_relative_gain > 0.1 && cam1_relative_gain < 10.0, "cam1_relative_gain",
                      "{}", cam1_relative_gain);
  PKSLAM_CHECK_OPTION(gain_flicker[0] >= 0.0 && gain_flicker[0] < 0.5 && gain_flicker[1] >= 0.0 &&
                          gain_flicker[1] < 0.5,
                      "gain_flicker", "{} {}", gain_flicker[0], gain_flicker[1]);
  if (trajectory.empty()) motion.Check();
  replay.Check();
  scene_build.Check();
  imu.Check();
  sensor.Check();
  realism.Check();
}

void ApplyAppearance(const AppearanceOptions& a, SimulationOptions* o) {
  a.Check();
  SensorOptions& s = o->sensor;
  s.read_noise_dn = a.read_noise_dn;
  s.shot_noise_gain = a.shot_noise_gain;
  s.blur_sigma_px = a.blur_sigma_px;
  s.vignetting = a.vignetting;
  s.target_brightness = a.target_brightness;
  s.exposure_adapt = a.exposure_adapt;
  s.clip_metering = true;
  s.max_exposure_s = 1e-3 * a.max_exposure_ms;
  s.exposure_at_unit_gain_s = 1e-3 * a.exposure_at_unit_gain_ms;
  o->cam1_relative_gain = a.cam1_relative_gain;
  o->gain_flicker = {1e-2 * a.gain_flicker_percent, 1e-2 * a.cam1_gain_flicker_percent};
  s.veiling_glare = 1e-2 * a.veiling_glare_percent;
}

std::string DefaultScene(const RealismOptions& realism, const std::filesystem::path& trajectory) {
  const std::string stem = trajectory.filename().string();
  const bool machine_hall = stem.rfind("MH", 0) == 0;
  if (!realism.On(RealismSource::kAppearance)) return machine_hall ? "machine_hall" : "vicon_room";
  return machine_hall ? realism.appearance.machine_hall_scene : realism.appearance.vicon_scene;
}

namespace {

void Vec(YAML::Emitter& e, const char* key, const Eigen::Vector3d& v) {
  e << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq << v.x() << v.y() << v.z()
    << YAML::EndSeq;
}

}  // namespace

void WriteSimYaml(const std::filesystem::path& file, const SimulationOptions& o,
                  const SimulationSummary& s) {
  YAML::Emitter e;
  e.SetDoublePrecision(17);
  e << YAML::BeginMap;
  e << YAML::Key << "generator" << YAML::Value << std::string("pkslam simulate ") + PKSLAM_VERSION;
  e << YAML::Key << "seed" << YAML::Value << o.seed;
  e << YAML::Key << "layout" << YAML::Value << s.layout;
  e << YAML::Key << "quality" << YAML::Value << QualityName(o.quality);
  e << YAML::Key << "motion" << YAML::Value << YAML::BeginMap;
  if (!o.trajectory.empty()) {
    e << YAML::Key << "replay" << YAML::Value << o.trajectory.string();
    e << YAML::Key << "start_s" << YAML::Value << o.start_s;
    e << YAML::Key << "position_knot_s" << YAML::Value << o.replay.position_knot_s;
    e << YAML::Key << "rotation_knot_s" << YAML::Value << o.replay.rotation_knot_s;
    e << YAML::Key << "position_cutoff_hz" << YAML::Value << o.replay.position_cutoff_hz;
    e << YAML::Key << "rotation_cutoff_hz" << YAML::Value << o.replay.rotation_cutoff_hz;
  } else {
    e << YAML::Key << "random" << YAML::Value << MotionLevelName(o.motion.level);
    e << YAML::Key << "rest_s" << YAML::Value << o.motion.rest_s;
    e << YAML::Key << "clearance_m" << YAML::Value << o.motion.clearance_m;
    e << YAML::Key << "view_m" << YAML::Value << YAML::Flow << YAML::BeginSeq << o.motion.min_view_m
      << o.motion.max_view_m << YAML::EndSeq;
  }
  e << YAML::Key << "duration_s" << YAML::Value
    << 1e-9 * static_cast<double>(s.end_ns - s.begin_ns);
  e << YAML::Key << "begin_ns" << YAML::Value << s.begin_ns;
  e << YAML::Key << "end_ns" << YAML::Value << s.end_ns;
  e << YAML::Key << "path_length_m" << YAML::Value << s.path_length_m;
  e << YAML::Key << "mean_speed_mps" << YAML::Value << s.mean_speed_mps;
  e << YAML::Key << "mean_angular_rate_dps" << YAML::Value << s.mean_angular_rate_dps;
  e << YAML::Key << "max_angular_rate_dps" << YAML::Value << s.max_angular_rate_dps;
  e << YAML::EndMap;

  e << YAML::Key << "scene" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "name" << YAML::Value << o.scene;
  e << YAML::Key << "texture_mode" << YAML::Value << TextureModeName(o.scene_build.texture_mode);
  e << YAML::Key << "texture_size" << YAML::Value << o.scene_build.texture_size;
  e << YAML::Key << "clearance_m" << YAML::Value << o.scene_build.clearance_m;
  Vec(e, "room_min", s.scene.room_min);
  Vec(e, "room_max", s.scene.room_max);
  e << YAML::Key << "objects_placed" << YAML::Value << s.scene.objects_placed;
  e << YAML::Key << "objects_removed" << YAML::Value << s.scene.objects_removed;
  e << YAML::Key << "missing_photos" << YAML::Value << YAML::Flow << s.scene.missing_photos;
  e << YAML::EndMap;

  e << YAML::Key << "imu" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "written" << YAML::Value << o.write_imu;
  e << YAML::Key << "rate_hz" << YAML::Value << o.imu.rate_hz;
  e << YAML::Key << "noise" << YAML::Value << o.imu.noise;
  e << YAML::Key << "gyro_noise_density" << YAML::Value << o.imu.gyro_noise_density;
  e << YAML::Key << "gyro_random_walk" << YAML::Value << o.imu.gyro_random_walk;
  e << YAML::Key << "accel_noise_density" << YAML::Value << o.imu.accel_noise_density;
  e << YAML::Key << "accel_random_walk" << YAML::Value << o.imu.accel_random_walk;
  Vec(e, "initial_gyro_bias", o.imu.initial_gyro_bias);
  Vec(e, "initial_accel_bias", o.imu.initial_accel_bias);
  e << YAML::Key << "vibration" << YAML::Value << o.imu.vibration;
  e << YAML::Key << "vibration_accel_rms" << YAML::Value << o.imu.vibration_accel_rms;
  e << YAML::Key << "vibration_gyro_rms" << YAML::Value << o.imu.vibration_gyro_rms;
  e << YAML::Key << "gravity" << YAML::Value << o.imu.gravity;
  e << YAML::EndMap;

  e << YAML::Key << "camera" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "rate_hz" << YAML::Value << (o.rgbd ? o.rgbd_rate_hz : o.camera_rate_hz);
  if (!o.rgbd) e << YAML::Key << "rig" << YAML::Value << o.camera;
  e << YAML::Key << "vignetting" << YAML::Value << o.sensor.vignetting;
  e << YAML::Key << "blur_sigma_px" << YAML::Value << o.sensor.blur_sigma_px;
  e << YAML::Key << "read_noise_dn" << YAML::Value << o.sensor.read_noise_dn;
  e << YAML::Key << "shot_noise_gain" << YAML::Value << o.sensor.shot_noise_gain;
  e << YAML::Key << "auto_exposure" << YAML::Value << o.sensor.auto_exposure;
  e << YAML::Key << "target_brightness" << YAML::Value << o.sensor.target_brightness;
  e << YAML::Key << "gain_drift" << YAML::Value << o.sensor.gain_drift;
  e << YAML::Key << "clip_metering" << YAML::Value << o.sensor.clip_metering;
  e << YAML::Key << "cam1_relative_gain" << YAML::Value << o.cam1_relative_gain;
  e << YAML::Key << "gain_flicker" << YAML::Value << YAML::Flow << YAML::BeginSeq
    << o.gain_flicker[0] << o.gain_flicker[1] << YAML::EndSeq;
  e << YAML::Key << "veiling_glare" << YAML::Value << o.sensor.veiling_glare;
  e << YAML::Key << "max_exposure_s" << YAML::Value << o.sensor.max_exposure_s;
  e << YAML::Key << "exposure_at_unit_gain_s" << YAML::Value << o.sensor.exposure_at_unit_gain_s;
  e << YAML::Key << "motion_blur_exposure_s" << YAML::Value << o.motion_blur_exposure_s;
  e << YAML::Key << "motion_blur_samples" << YAML::Value << o.motion_blur_samples;
  e << YAML::Key << "depth_noise" << YAML::Value << o.depth_noise;
  e << YAML::Key << "blackout_s" << YAML::Value << YAML::Flow << YAML::BeginSeq
    << o.blackout_begin_s << o.blackout_end_s << YAML::EndSeq;
  e << YAML::Key << "images_written" << YAML::Value << o.write_images;
  e << YAML::Key << "frames" << YAML::Value << s.frames;
  e << YAML::EndMap;

  const RealismOptions& r = o.realism;
  e << YAML::Key << "realism" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "preset" << YAML::Value << RealismPresetName(r.preset);
  e << YAML::Key << "device_seed" << YAML::Value << r.device_seed;
  e << YAML::Key << "sources" << YAML::Value << YAML::BeginMap;
  for (RealismSource source : kRealismSources) {
    e << YAML::Key << RealismSourceName(source) << YAML::Value << r.On(source);
  }
  e << YAML::EndMap;
  e << YAML::Key << "vibration" << YAML::Value << r.motion.vibration;
  e << YAML::Key << "parameters" << YAML::Value << YAML::BeginSeq;
  for (const RealismEntry& entry : RealismReport(r)) {
    e << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << entry.name
      << YAML::Key << "value" << YAML::Value << entry.value << YAML::Key << "unit" << YAML::Value
      << entry.unit << YAML::Key << "documented" << YAML::Value << entry.range << YAML::Key
      << "source" << YAML::Value << entry.reference << YAML::EndMap;
  }
  e << YAML::EndSeq;
  e << YAML::Key << "mean_exposure_ms" << YAML::Value << s.mean_exposure_ms;
  e << YAML::Key << "saturated_share" << YAML::Value << s.saturated_share;
  e << YAML::EndMap;

  e << YAML::Key << "landmark_tracks" << YAML::Value << o.landmark_tracks;
  e << YAML::Key << "reference_cloud" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "written" << YAML::Value << o.write_cloud;
  e << YAML::Key << "spacing_m" << YAML::Value << o.cloud_spacing_m;
  e << YAML::Key << "visibility_cell_m" << YAML::Value << o.visibility_cell_m;
  e << YAML::Key << "points" << YAML::Value << s.cloud_points;
  e << YAML::Key << "observed_range_m" << YAML::Value << o.observed_range_m;
  e << YAML::Key << "observed_cell_m" << YAML::Value << o.observed_cell_m;
  e << YAML::Key << "observed_points" << YAML::Value << s.observed_points;
  e << YAML::EndMap;
  e << YAML::EndMap;

  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << e.c_str() << '\n';
  if (!out) throw Error("cannot write " + file.string());
}

}  // namespace pkslam::sim
