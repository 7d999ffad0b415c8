#include "dense/keyframe_images.h"

#include <algorithm>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/util/error.h"
#include "io/settings_euroc.h"

namespace pkslam::dense {

namespace fs = std::filesystem;

KeyframeImageSource KeyframeImageSource::Open(const fs::path& dataset,
                                              const std::optional<fs::path>& settings) {
  if (!fs::is_directory(dataset)) throw InputError(dataset, "dataset directory does not exist");
  KeyframeImageSource s;
  if (EurocDataset::LooksLikeEuroc(dataset)) {
    EurocOptions eo;
    eo.read_imu = true;  // as `pkslam run`: the IMU sensor carries the body frame
    s.euroc_ = EurocDataset::Open(dataset, eo);
    if (!s.euroc_->has_cam1()) {
      throw InputError(dataset, "dense stereo needs cam1 (the dataset has only cam0)");
    }
    s.source_ = DepthSource::kStereo;
    s.settings_ = settings ? ReadOrbSlam3Settings(*settings) : SettingsFromEuroc(*s.euroc_);
    s.settings_.Check();
    if (!s.settings_.IsStereo()) {
      throw OptionError("the settings have no stereo calibration (Camera2.*, Stereo.T_c1_c2)");
    }
    // The same construction as system/rig_factory.cc MakeRig (dense_test checks they agree).
    if (s.settings_.rectified_stereo) {
      s.camera_ = s.settings_.camera1;
      s.bf_ = s.camera_.fx() * s.settings_.BaselineM();
    } else {
      s.rectification_.emplace(s.settings_.camera1, *s.settings_.camera2,
                               *s.settings_.right_from_left);
      s.camera_ = s.rectification_->rectified_camera();
      s.bf_ = s.rectification_->bf();
    }
    for (const StereoPair& p : s.euroc_->stereo_pairs()) {
      s.timestamps_.push_back(p.t_ns);
      s.frames_.emplace_back(p.left, p.right);
    }
  } else if (TumRgbdDataset::LooksLikeTumRgbd(dataset)) {
    s.tum_ = TumRgbdDataset::Open(dataset);
    s.source_ = DepthSource::kRgbd;
    const fs::path fallback = dataset / "settings.yaml";
    if (!settings && !fs::exists(fallback)) {
      throw InputError(dataset,
                       "TUM RGB-D layout needs --settings (or settings.yaml in the dataset)");
    }
    s.settings_ = ReadOrbSlam3Settings(settings.value_or(fallback));
    if (!s.settings_.depth_map_factor) s.settings_.depth_map_factor = s.tum_->depth_factor();
    s.settings_.Check();
    s.camera_ = s.settings_.camera1;
    for (const RgbdAssociation& a : s.tum_->associations()) {
      s.timestamps_.push_back(s.tum_->rgb().images[a.rgb].t_ns);
      s.frames_.emplace_back(a.rgb, a.depth);
    }
  } else {
    throw InputError(dataset,
                     "not a EuRoC (mav0/cam0/data.csv) or TUM RGB-D (rgb.txt, depth.txt) dataset");
  }
  if (s.camera_.type() != CameraType::kPinhole) {
    throw OptionError("dense reconstruction supports pinhole (radial-tangential) cameras");
  }
  return s;
}

CameraModel KeyframeImageSource::PinholeCamera() const {
  return CameraModel::Pinhole(camera_.width(), camera_.height(), camera_.fx(), camera_.fy(),
                              camera_.cx(), camera_.cy());
}

std::optional<std::size_t> KeyframeImageSource::FindFrame(std::int64_t t_ns) const {
  const auto it = std::lower_bound(timestamps_.begin(), timestamps_.end(), t_ns);
  if (it == timestamps_.end() || *it != t_ns) return std::nullopt;
  return static_cast<std::size_t>(it - timestamps_.begin());
}

KeyframeImages KeyframeImageSource::Load(std::size_t index) const {
  PKSLAM_CHECK(index < frames_.size(), "frame {} of {}", index, frames_.size());
  KeyframeImages out;
  out.t_ns = timestamps_[index];
  const auto [a, b] = frames_[index];
  if (euroc_) {
    const cv::Mat left = euroc_->LoadCam0(a);
    const cv::Mat right = euroc_->LoadCam1(b);
    if (rectification_) {
      std::tie(out.grey, out.right) = rectification_->Rectify(left, right);
    } else {
      out.grey = left;
      out.right = right;
    }
  } else {
    out.colour = tum_->LoadRgbColour(a);
    cv::cvtColor(out.colour, out.grey, cv::COLOR_BGR2GRAY);
    const cv::Mat raw = tum_->LoadDepthRaw(b);
    raw.convertTo(out.depth_m, CV_32F, 1.0 / *settings_.depth_map_factor);
  }
  return out;
}

cv::Mat UndistortImage(const cv::Mat& image, const CameraModel& camera) {
  if (!camera.HasDistortion()) return image;
  cv::Mat out;
  cv::undistort(image, out, camera.CvK(), camera.CvDistortion(), camera.CvK());
  return out;
}

}  // namespace pkslam::dense
