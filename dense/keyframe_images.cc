#include "dense/keyframe_images.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/util/error.h"
#include "io/settings_euroc.h"

namespace pkslam::dense {

namespace fs = std::filesystem;

namespace {

// Rectified pixel -> raw pixel maps of one camera for an ideal pinhole `canvas` whose frame is
// rect_from_raw * raw frame; pixels whose ray does not reach the raw image get -1 (remap's
// constant border) and 0 in `valid`.
void FullViewMaps(const CameraModel& raw, const SO3d& rect_from_raw, const CameraModel& canvas,
                  cv::Mat* map_x, cv::Mat* map_y, cv::Mat* valid) {
  const Eigen::Matrix3d raw_from_rect = rect_from_raw.Inverse().Matrix();
  map_x->create(canvas.height(), canvas.width(), CV_32FC1);
  map_y->create(canvas.height(), canvas.width(), CV_32FC1);
  valid->create(canvas.height(), canvas.width(), CV_8UC1);
  for (int r = 0; r < canvas.height(); ++r) {
    auto* mx = map_x->ptr<float>(r);
    auto* my = map_y->ptr<float>(r);
    auto* ok = valid->ptr<std::uint8_t>(r);
    for (int c = 0; c < canvas.width(); ++c) {
      const Eigen::Vector3d ray((c - canvas.cx()) / canvas.fx(), (r - canvas.cy()) / canvas.fy(),
                                1.0);
      const auto uv = raw.Project(raw_from_rect * ray);
      const bool inside = uv && uv->x() >= 0 && uv->y() >= 0 && uv->x() <= raw.width() - 1 &&
                          uv->y() <= raw.height() - 1;
      mx[c] = inside ? static_cast<float>(uv->x()) : -1.0f;
      my[c] = inside ? static_cast<float>(uv->y()) : -1.0f;
      ok[c] = inside ? 255 : 0;
    }
  }
}

// The run's rectified pinhole grown (same fx, fy) to the bounding box of both raw images'
// borders, at most `max_growth` times the raw size per axis.
CameraModel FullViewCanvas(const StereoRectification& rect, double max_growth) {
  const CameraModel& k = rect.rectified_camera();
  double u0 = 0, v0 = 0, u1 = k.width() - 1, v1 = k.height() - 1;
  auto extend = [&](const CameraModel& raw, const SO3d& rect_from_raw) {
    const int w = raw.width(), h = raw.height();
    std::vector<Eigen::Vector2d> border;
    for (int x = 0; x < w; ++x) border.insert(border.end(), {{x, 0.0}, {x, h - 1.0}});
    for (int y = 0; y < h; ++y) border.insert(border.end(), {{0.0, y}, {w - 1.0, y}});
    for (const Eigen::Vector2d& uv : border) {
      const Eigen::Vector3d q = rect_from_raw * raw.Unproject(uv);
      if (q.z() <= 1e-3) continue;
      u0 = std::min(u0, k.fx() * q.x() / q.z() + k.cx());
      u1 = std::max(u1, k.fx() * q.x() / q.z() + k.cx());
      v0 = std::min(v0, k.fy() * q.y() / q.z() + k.cy());
      v1 = std::max(v1, k.fy() * q.y() / q.z() + k.cy());
    }
  };
  extend(rect.left_camera(), rect.rect_left_from_left());
  extend(rect.right_camera(), rect.rect_right_from_right());
  const double grow_u = 0.5 * (max_growth - 1.0) * k.width();
  const double grow_v = 0.5 * (max_growth - 1.0) * k.height();
  const int left = static_cast<int>(std::ceil(std::min(-u0, grow_u)));
  const int top = static_cast<int>(std::ceil(std::min(-v0, grow_v)));
  const int right = static_cast<int>(std::ceil(std::min(u1 - (k.width() - 1), grow_u)));
  const int bottom = static_cast<int>(std::ceil(std::min(v1 - (k.height() - 1), grow_v)));
  return CameraModel::Pinhole(k.width() + left + right, k.height() + top + bottom, k.fx(), k.fy(),
                              k.cx() + left, k.cy() + top);
}

}  // namespace

KeyframeImageSource KeyframeImageSource::Open(const fs::path& dataset,
                                              const std::optional<fs::path>& settings,
                                              bool full_view) {
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
      if (full_view) {
        s.camera_ = FullViewCanvas(*s.rectification_, 1.5);
        cv::Mat left_valid, right_valid;
        FullViewMaps(s.rectification_->left_camera(), s.rectification_->rect_left_from_left(),
                     s.camera_, &s.left_map_x_, &s.left_map_y_, &left_valid);
        FullViewMaps(s.rectification_->right_camera(), s.rectification_->rect_right_from_right(),
                     s.camera_, &s.right_map_x_, &s.right_map_y_, &right_valid);
        // A left pixel needs its right match inside the raw right image: at zero disparity or
        // to its left on the same row, so rows the right image does not reach are dropped;
        // the stereo matcher and its left-right check handle the columns.
        s.valid_mask_ = left_valid.clone();
        for (int r = 0; r < right_valid.rows; ++r) {
          if (cv::countNonZero(right_valid.row(r)) == 0) s.valid_mask_.row(r).setTo(0);
        }
      }
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
  if (it != timestamps_.end() && *it == t_ns) {
    return static_cast<std::size_t>(it - timestamps_.begin());
  }
  // Inertial runs with a camera-IMU time offset stamp their poses on the IMU clock (image stamp
  // + offset, a few ms): the nearest image within a quarter of the frame interval is the one.
  if (timestamps_.size() < 2) return std::nullopt;
  const std::int64_t tolerance = (timestamps_.back() - timestamps_.front()) /
                                 static_cast<std::int64_t>(timestamps_.size() - 1) / 4;
  std::optional<std::size_t> best;
  std::int64_t best_gap = tolerance + 1;
  for (auto candidate : {it, it == timestamps_.begin() ? it : it - 1}) {
    if (candidate == timestamps_.end()) continue;
    const std::int64_t gap = std::abs(*candidate - t_ns);
    if (gap < best_gap) {
      best_gap = gap;
      best = static_cast<std::size_t>(candidate - timestamps_.begin());
    }
  }
  return best;
}

KeyframeImages KeyframeImageSource::Load(std::size_t index) const {
  PKSLAM_CHECK(index < frames_.size(), "frame {} of {}", index, frames_.size());
  KeyframeImages out;
  out.t_ns = timestamps_[index];
  const auto [a, b] = frames_[index];
  if (euroc_) {
    const cv::Mat left = euroc_->LoadCam0(a);
    const cv::Mat right = euroc_->LoadCam1(b);
    if (!left_map_x_.empty()) {
      cv::remap(left, out.grey, left_map_x_, left_map_y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
      cv::remap(right, out.right, right_map_x_, right_map_y_, cv::INTER_LINEAR,
                cv::BORDER_CONSTANT);
    } else if (rectification_) {
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
