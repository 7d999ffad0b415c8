#include "system/run_input.h"

#include <algorithm>
#include <future>

#include "core/camera/stereo_rectification.h"
#include "core/util/error.h"
#include "io/kitti_dataset.h"
#include "io/settings_euroc.h"
#include "system/run_dataset.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

// EuRoC ASL, or a KITTI sequence, which runs as an EuRoC dataset of its two image streams (no
// IMU, no sensor files), with the settings calib.txt gives unless --settings names a file.
void OpenEuroc(const RunOptions& options, const std::optional<KittiSequence>& kitti,
               InputReport* report, RunInput* in) {
  const Sensor sensor = in->sensor;
  EurocOptions eo;
  // The IMU sensor carries the body frame (EuRoC ground truth) even for visual-only runs.
  eo.read_imu = true;
  eo.imu_limits = options.imu_limits;
  in->euroc = kitti ? EurocDataset::FromImageStreams(options.dataset, kitti->left, kitti->right)
                    : EurocDataset::Open(options.dataset, eo);
  const EurocDataset& euroc = *in->euroc;
  if (kitti && IsInertial(sensor)) {
    throw OptionError("a KITTI odometry sequence has no IMU: use stereo or mono");
  }
  if (IsRgbd(sensor)) throw OptionError("an EuRoC dataset has no depth: use stereo or mono");
  if (IsInertial(sensor) && !euroc.has_imu()) {
    throw InputError(euroc.mav0() / "imu0", fmt::format("sensor {} needs IMU data (imu0/ "
                                                        "with sensor.yaml and data.csv): "
                                                        "missing",
                                                        SensorName(sensor)));
  }
  if (IsStereo(sensor)) {
    if (!euroc.has_cam1()) {
      throw InputError(euroc.mav0() / "cam1",
                       fmt::format("sensor {} needs cam1 (missing)", SensorName(sensor)));
    }
    for (const auto& p : euroc.stereo_pairs()) in->frames.push_back({p.t_ns, p.left, p.right});
    // cam1 with fewer rows dropped frames with an info-level note only.
    const std::size_t listed = std::max(euroc.cam0().images.size(), euroc.cam1().images.size());
    report->frames_skipped = static_cast<int>(listed - in->frames.size());
    if (report->frames_skipped > 0) {
      report->Warn(
          fmt::format("{}: {} of {} frames skipped: cam0 has {} images, cam1 {}, {} with the same "
                      "timestamp in both",
                      euroc.mav0().string(), report->frames_skipped, listed,
                      euroc.cam0().images.size(), euroc.cam1().images.size(), in->frames.size()));
    }
  } else {
    const auto& images = euroc.cam0().images;
    for (std::size_t i = 0; i < images.size(); ++i) in->frames.push_back({images[i].t_ns, i, 0});
  }
  in->settings = options.settings ? ReadOrbSlam3Settings(*options.settings)
                 : kitti          ? SettingsFromKitti(*kitti)
                                  : SettingsFromEuroc(euroc);
  const Settings& settings = in->settings;
  if (IsStereo(sensor) && settings.camera2 && settings.right_from_left) {
    // Checked here, where the calibration's file is known, to name it.
    try {
      StereoRectification::Check(settings.camera1, *settings.camera2, *settings.right_from_left);
    } catch (const OptionError& e) {
      throw InputError(options.settings.value_or(euroc.mav0() / "cam1" / "sensor.yaml"), e.what());
    }
  }
}

void OpenTum(const RunOptions& options, InputReport* report, RunInput* in) {
  const Sensor sensor = in->sensor;
  in->tum = TumRgbdDataset::Open(options.dataset);
  TumRgbdDataset& tum = *in->tum;
  if (IsStereo(sensor)) throw OptionError("a TUM RGB-D dataset has no stereo pair");
  if (IsRgbd(sensor)) {
    for (const auto& a : tum.associations()) {
      in->frames.push_back({tum.rgb().images[a.rgb].t_ns, a.rgb, a.depth});
    }
    tum.RequireValidDepth();
    report->frames_skipped = static_cast<int>(tum.rgb().images.size() - in->frames.size());
    if (report->frames_skipped > 0) {
      report->Warn(
          fmt::format("{}: {} of {} rgb frames skipped: no depth image within the "
                      "association window",
                      options.dataset.string(), report->frames_skipped, tum.rgb().images.size()));
    }
  } else {
    const auto& images = tum.rgb().images;
    for (std::size_t i = 0; i < images.size(); ++i) in->frames.push_back({images[i].t_ns, i, 0});
  }
  const fs::path fallback = options.dataset / "settings.yaml";
  if (!options.settings && !fs::exists(fallback)) {
    throw InputError(options.dataset,
                     "TUM RGB-D layout needs --settings (or settings.yaml in the dataset)");
  }
  in->settings = ReadOrbSlam3Settings(options.settings.value_or(fallback));
  Settings& settings = in->settings;
  if (!settings.depth_map_factor) settings.depth_map_factor = tum.depth_factor();
  if (IsRgbd(sensor)) {
    tum.CheckDepthScale(*settings.depth_map_factor,
                        "RGBD.DepthMapFactor of " + options.settings.value_or(fallback).string());
  }
}

// --first-frame, then --max-frames of the rest.
void SelectFrames(const RunOptions& options, std::vector<DatasetFrame>* frames) {
  if (options.first_frame > 0) {
    if (options.first_frame >= static_cast<int>(frames->size())) {
      throw InputError(options.dataset, fmt::format("--first-frame {}: the dataset has {} frames",
                                                    options.first_frame, frames->size()));
    }
    frames->erase(frames->begin(), frames->begin() + options.first_frame);
  }
  if (options.max_frames > 0 && static_cast<int>(frames->size()) > options.max_frames) {
    frames->resize(options.max_frames);
  }
}

// Images of another size than the calibration's were tracked with wrong intrinsics
// (monocular) or failed deep in the rectification (stereo, RGB-D), naming no image.
void RequireSize(const cv::Mat& image, const CameraModel& camera, const fs::path& path) {
  if (image.cols != camera.width() || image.rows != camera.height()) {
    throw InputError(path, fmt::format("{}x{} image, but the calibration is {}x{}", image.cols,
                                       image.rows, camera.width(), camera.height()));
  }
}

}  // namespace

RunInput OpenRunInput(const RunOptions& options, InputReport* report) {
  RunInput in;
  in.sensor = options.system.sensor;
  std::optional<KittiSequence> kitti;
  if (LooksLikeKitti(options.dataset)) {
    KittiOptions ko;
    ko.colour = options.kitti_colour;
    kitti = OpenKittiSequence(options.dataset, ko);
  }
  if (kitti || EurocDataset::LooksLikeEuroc(options.dataset)) {
    OpenEuroc(options, kitti, report, &in);
  } else if (TumRgbdDataset::LooksLikeTumRgbd(options.dataset)) {
    OpenTum(options, report, &in);
  } else {
    throw InputError(options.dataset,
                     "not a EuRoC (mav0/cam0/data.csv) or TUM RGB-D (rgb.txt, depth.txt) dataset");
  }
  if (in.frames.empty()) throw InputError(options.dataset, "no frames to process");
  SelectFrames(options, &in.frames);
  return in;
}

std::vector<std::int64_t> RunInput::FrameTimes() const {
  std::vector<std::int64_t> t_ns;
  t_ns.reserve(frames.size());
  for (const DatasetFrame& s : frames) t_ns.push_back(s.t_ns);
  return t_ns;
}

// A pair's second image (right / depth) is decoded concurrently with its first: decoding a
// 640x480 colour PNG takes about 8 ms and its depth PNG 3 ms, so one loader thread in series
// capped 30 Hz RGB-D at 2.8x real time.
LoadedImages RunInput::Load(std::size_t k) const {
  const DatasetFrame& s = frames[k];
  std::future<cv::Mat> second;  // its destructor waits, also when the first one throws
  if (euroc && IsStereo(sensor)) {
    second = std::async(std::launch::async, [&] { return euroc->LoadCam1(s.b); });
  } else if (tum && IsRgbd(sensor)) {
    second = std::async(std::launch::async, [&] { return tum->LoadDepthRaw(s.b); });
  }
  LoadedImages loaded;
  loaded.a = euroc ? euroc->LoadCam0(s.a) : tum->LoadRgbGrey(s.a);
  if (second.valid()) loaded.b = second.get();
  loaded.no_depth = tum && IsRgbd(sensor) && cv::countNonZero(loaded.b) == 0;
  RequireSize(loaded.a, settings.camera1,
              euroc ? euroc->cam0().images[s.a].path : tum->rgb().images[s.a].path);
  if (euroc && IsStereo(sensor)) {
    RequireSize(loaded.b, settings.camera2.value_or(settings.camera1),
                euroc->cam1().images[s.b].path);
  } else if (tum && IsRgbd(sensor)) {
    RequireSize(loaded.b, settings.camera1, tum->depth().images[s.b].path);
  }
  return loaded;
}

}  // namespace pkslam
