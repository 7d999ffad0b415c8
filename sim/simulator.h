// `pkslam simulate`: one call produces a complete sequence with exact ground truth.
//   EuRoC mode (default): DIR/mav0/... (stereo + IMU + ground truth, see euroc_writer.h),
//     DIR/settings.yaml (ORB-SLAM3 format), DIR/timestamps.txt.
//   RGB-D mode: TUM RGB-D layout (rgb/, depth/, rgb.txt, depth.txt, associations.txt,
//     groundtruth.txt of the colour camera), DIR/settings.yaml.
//   Both: DIR/reference_cloud.ply (every surface cam0 saw), DIR/reference_observed.ply (the
//     surfaces cam0 saw within observed_range_m: the surveyed area), DIR/sim.yaml (every
//     option + seed). reference_only renders cam0 for the two clouds and writes nothing else
//     (to add them to a sequence rendered earlier with the same options).
// Same options and seed -> identical bytes.
//
// Threads: RunSimulation drives frames sequentially on the calling thread; rendering and
// image formation use TBB inside each frame, and the PNG files of frame k are encoded by a
// TBB task while frame k+1 renders (list files are written in order by the calling thread).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include "sim/imu_simulator.h"
#include "sim/landmark_tracks.h"
#include "sim/motion_generator.h"
#include "sim/motion_trajectory.h"
#include "sim/realism.h"
#include "sim/renderer.h"
#include "sim/scene_builder.h"
#include "sim/sensor_model.h"

namespace pkslam::sim {

enum class Quality { kFast, kDefault, kHigh };
Quality ParseQuality(const std::string& name);  // fast|default|high; OptionError
std::string QualityName(Quality quality);

struct SimulationOptions {
  std::filesystem::path output_dir;  // created if missing
  std::filesystem::path trajectory;  // replay this ground truth (TUM/EuRoC); empty: random
  MotionOptions motion;              // random motion (level, duration, clearances)
  double start_s = 0.0;              // replay: start offset into the trajectory file
  double duration_s = 0.0;           // 0: replay to the file's end / random: motion.duration_s
  std::string scene = "vicon_room";  // built-in name or YAML file
  std::string texture_mode;          // rich|weak|repetitive; empty: the scene's default
  std::uint64_t seed = 1;
  Quality quality = Quality::kDefault;
  ReplayOptions replay;
  SceneBuildOptions scene_build;  // texture_size and colour follow quality / rgbd
  ImuOptions imu;
  bool write_imu = true;
  bool write_images = true;      // false: IMU + ground truth only (no rendering)
  double camera_rate_hz = 20.0;  // stereo cameras (EuRoC: 20, KITTI: 10)
  // Stereo rig of EuRoC-format output: euroc | kitti | vga (StereoRig in euroc_writer.h).
  std::string camera = "euroc";
  SensorOptions sensor;
  double cam1_relative_gain = 1.0;      // cam1's response relative to cam0's (gain of its images)
  // Relative std of each camera's independent frame-to-frame gain change (cam0, cam1): the
  // exposure flicker a real sensor shows on a static scene (0: none).
  std::array<double, 2> gain_flicker{0.0, 0.0};
  double motion_blur_exposure_s = 0.0;  // > 0: average sub-renders over this exposure
  int motion_blur_samples = 0;          // sub-renders (0: by quality: 3 / 5 / 9)
  bool rgbd = false;                    // TUM RGB-D output instead of EuRoC
  double rgbd_rate_hz = 30.0;
  double depth_noise = 1.0;        // x the Kinect depth noise model (0: exact depth)
  double blackout_begin_s = -1.0;  // images in [begin, end] (s from start) are black
  double blackout_end_s = -1.0;
  bool write_cloud = true;          // reference_cloud.ply (+ reference_observed.ply)
  double cloud_spacing_m = 0.01;    // point spacing on the surfaces
  double visibility_cell_m = 0.05;  // granularity of "seen" surface cells
  // reference_observed.ply: surfaces cam0 saw at a depth (optical axis) <= this, in any
  // frame (0: not written): the surveyed area. Below the dense tool's 4 m depth limit, as
  // keyframes see what the frames between them saw from a little farther away.
  double observed_range_m = 3.0;
  double observed_cell_m = 0.02;  // granularity of its "seen" cells
  // > 0: exact 2-D tracks of this many surface landmarks in cam0 (landmark_tracks.h), written
  // to DIR/truth/tracks_*.txt for `pkslam tracks export --simulated`.
  int landmark_tracks = 0;
  // Render cam0 only for the reference clouds; write no images, IMU or sim.yaml.
  bool reference_only = false;
  bool bench = false;      // render and develop only; write nothing
  int bench_frames = 200;  // frames rendered by bench (0: the whole sequence)
  bool quiet = false;      // no progress bar
  // Error sources of real recordings (calibration, timing, IMU axes, vibration, ground truth;
  // appearance comes through `sensor` and `scene`, see ApplyAppearance). Default: ideal.
  RealismOptions realism;

  void Check() const;
};

// Sets the sensor model (noise, blur, vignetting, auto exposure, exposure time and motion blur)
// to the realism preset's appearance. The CLI applies it first and the user's explicit flags on
// top.
void ApplyAppearance(const AppearanceOptions& appearance, SimulationOptions* options);

// The scene a sequence gets under `realism` when the user names none: the appearance's
// machine-hall scene for trajectories whose file name starts with "MH", its Vicon-room scene
// otherwise (random flights included).
std::string DefaultScene(const RealismOptions& realism, const std::filesystem::path& trajectory);

struct SimulationSummary {
  std::string layout;  // "euroc" | "tum_rgbd" | "bench" | "reference"
  std::int64_t begin_ns = 0;
  std::int64_t end_ns = 0;
  int frames = 0;  // camera frames (stereo pairs or RGB-D frames)
  int image_width = 0;
  int image_height = 0;
  int imu_samples = 0;
  double path_length_m = 0.0;  // of the body over [begin, end] at the IMU rate
  double mean_speed_mps = 0.0;
  double mean_angular_rate_dps = 0.0;
  double max_angular_rate_dps = 0.0;
  double render_seconds = 0.0;      // rendering + image formation only
  double frames_per_second = 0.0;   // frames / render_seconds
  double render_cpu_seconds = 0.0;  // process CPU time (all threads) of the same work; in
                                    // file-writing runs it includes overlapping PNG encoding
  double total_seconds = 0.0;       // wall time of the frame loop including image files
  std::size_t cloud_points = 0;
  std::size_t observed_points = 0;  // reference_observed.ply
  double mean_exposure_ms = 0.0;    // exposure model on: mean exposure of the frames
  double saturated_share = 0.0;     // share of cam0 pixels at 255 (mean over frames)
  SceneBuildReport scene;
};

SimulationSummary RunSimulation(const SimulationOptions& options);

// Writes DIR/sim.yaml (all options, seed, summary, version).
void WriteSimYaml(const std::filesystem::path& file, const SimulationOptions& options,
                  const SimulationSummary& summary);

}  // namespace pkslam::sim
