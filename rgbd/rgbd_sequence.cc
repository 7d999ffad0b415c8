#include "rgbd/rgbd_sequence.h"

#include <fmt/format.h>

#include <algorithm>

#include "core/util/error.h"
#include "core/util/log.h"
#include "io/settings.h"

namespace pkslam::rgbd {
namespace fs = std::filesystem;

void RgbdSequenceOptions::Check() const {
  PKSLAM_CHECK_OPTION(depth_factor >= 0, "depth_factor", "{}", depth_factor);
  PKSLAM_CHECK_OPTION(max_frames >= 0, "max_frames", "{}", max_frames);
  PKSLAM_CHECK_OPTION(first_frame >= 0, "first_frame", "{}", first_frame);
}

namespace {

// TUM's published Kinect calibrations (the benchmark's "intrinsic camera calibration" page).
std::optional<CameraModel> TumDefaultCamera(const fs::path& root, std::string* source) {
  fs::path folder = fs::absolute(root).lexically_normal();
  if (folder.filename().empty()) folder = folder.parent_path();  // "dir/" -> "dir"
  const std::string name = folder.filename().string();
  if (name.find("freiburg1") != std::string::npos) {
    *source = "TUM freiburg1 calibration (from the folder name)";
    return CameraModel::Pinhole(640, 480, 517.306408, 516.469215, 318.643040, 255.313989,
                                {0.262383, -0.953104, -0.005358, 0.002628, 1.163314});
  }
  if (name.find("freiburg2") != std::string::npos) {
    *source = "TUM freiburg2 calibration (from the folder name)";
    return CameraModel::Pinhole(640, 480, 520.908620, 521.007327, 325.141442, 249.701764,
                                {0.231222, -0.784899, -0.003257, -0.000105, 0.917205});
  }
  if (name.find("freiburg3") != std::string::npos) {
    *source = "TUM freiburg3 calibration (from the folder name)";
    return CameraModel::Pinhole(640, 480, 535.4, 539.2, 320.1, 247.6);
  }
  return std::nullopt;
}

}  // namespace

RgbdSequence OpenRgbdSequence(const RgbdSequenceOptions& options) {
  options.Check();
  if (!fs::is_directory(options.dataset)) {
    throw InputError(options.dataset, "dataset directory not found");
  }
  if (!TumRgbdDataset::LooksLikeTumRgbd(options.dataset)) {
    throw InputError(options.dataset, "not a TUM RGB-D folder (rgb.txt and depth.txt expected)");
  }
  TumRgbdOptions tum;
  tum.depth_factor = options.depth_factor;
  RgbdSequence seq{TumRgbdDataset::Open(options.dataset, tum), {}, {}, {}, {}};

  for (const ImageStream* stream : {&seq.dataset.rgb(), &seq.dataset.depth()}) {
    if (!stream->missing.empty() && !options.skip_missing) {
      throw InputError(
          stream->missing.front(),
          fmt::format("{} image listed in {} is missing ({} missing in all; "
                      "--skip-missing processes the rest)",
                      stream->name, stream->list_file.filename().string(), stream->missing.size()));
    }
  }

  const fs::path own_settings = options.dataset / "settings.yaml";
  if (options.settings) {
    seq.camera = ReadOrbSlam3Settings(*options.settings).camera1;
    seq.camera_source = options.settings->string();
  } else if (fs::is_regular_file(own_settings)) {
    seq.camera = ReadOrbSlam3Settings(own_settings).camera1;
    seq.camera_source = own_settings.string();
  } else if (auto camera = TumDefaultCamera(options.dataset, &seq.camera_source)) {
    seq.camera = *camera;
  } else {
    throw InputError(options.dataset,
                     "no camera intrinsics: pass --settings (an ORB-SLAM3 settings file) or put "
                     "settings.yaml in the dataset");
  }
  if (seq.camera.type() != CameraType::kPinhole) {
    throw InputError(seq.camera_source, "RGB-D needs a pinhole camera model");
  }

  const fs::path gt = options.dataset / "groundtruth.txt";
  if (fs::is_regular_file(gt)) seq.ground_truth = ReadTrajectory(gt, TrajectoryFormat::kTum);

  const auto& associations = seq.dataset.associations();
  if (associations.empty()) {
    throw InputError(options.dataset / "depth.txt",
                     "no colour image has a depth image within 20 ms");
  }
  const std::size_t first = static_cast<std::size_t>(options.first_frame);
  if (first >= associations.size()) {
    throw OptionError(
        fmt::format("--first-frame {}: the sequence has {} frames", first, associations.size()));
  }
  std::size_t end = associations.size();
  if (options.max_frames > 0)
    end = std::min(end, first + static_cast<std::size_t>(options.max_frames));
  for (std::size_t i = first; i < end; ++i) seq.frames.push_back(i);
  seq.dataset.RequireValidDepth();
  PKSLAM_LOG_INFO("rgbd: {} frames from {}; camera {} ({})", seq.frames.size(),
                  options.dataset.string(), seq.camera.ToString(), seq.camera_source);
  return seq;
}

RgbdFrame LoadRgbdFrame(const RgbdSequence& sequence, std::size_t k) {
  PKSLAM_CHECK(k < sequence.frames.size(), "frame {} of {}", k, sequence.frames.size());
  const RgbdAssociation& a = sequence.dataset.associations()[sequence.frames[k]];
  RgbdFrame frame;
  frame.t_ns = sequence.dataset.rgb().images[a.rgb].t_ns;
  frame.colour_bgr = sequence.dataset.LoadRgbColour(a.rgb);
  frame.depth_m = sequence.dataset.LoadDepthMetres(a.depth);
  const cv::Size expected(sequence.camera.width(), sequence.camera.height());
  if (frame.colour_bgr.size() != expected) {
    throw InputError(sequence.dataset.rgb().images[a.rgb].path,
                     fmt::format("image is {}x{}, the camera {}x{}", frame.colour_bgr.cols,
                                 frame.colour_bgr.rows, expected.width, expected.height));
  }
  if (frame.depth_m.size() != expected) {
    throw InputError(sequence.dataset.depth().images[a.depth].path,
                     fmt::format("depth image is {}x{}, the camera {}x{}", frame.depth_m.cols,
                                 frame.depth_m.rows, expected.width, expected.height));
  }
  return frame;
}

std::optional<SE3d> InterpolatePose(const Trajectory& trajectory, std::int64_t t_ns,
                                    std::int64_t max_gap_ns) {
  const auto& poses = trajectory.poses;
  const auto it = std::lower_bound(poses.begin(), poses.end(), t_ns,
                                   [](const StampedPose& p, std::int64_t t) { return p.t_ns < t; });
  if (it != poses.end() && it->t_ns == t_ns) return it->pose;
  if (it == poses.begin() || it == poses.end()) return std::nullopt;
  const StampedPose& before = *(it - 1);
  const StampedPose& after = *it;
  if (after.t_ns - before.t_ns > max_gap_ns) return std::nullopt;
  const double s =
      static_cast<double>(t_ns - before.t_ns) / static_cast<double>(after.t_ns - before.t_ns);
  return SE3d::Interpolate(before.pose, after.pose, s);
}

RelativePoseError CompareRelativePose(const SE3d& estimate, const SE3d& truth) {
  const SE3d error = truth.Inverse() * estimate;
  return {error.translation().norm(), error.so3().Angle() * 180.0 / M_PI};
}

}  // namespace pkslam::rgbd
