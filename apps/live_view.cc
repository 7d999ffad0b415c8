#include "apps/live_view.h"

#include <fmt/format.h>
#include <httplib.h>

#include <chrono>
#include <opencv2/imgcodecs.hpp>

#include "core/util/error.h"
#include "core/util/log.h"
#include "viewer/view_html.h"

namespace pkslam::apps {
namespace {

double WallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void AppendNumbers(std::string& out, const std::vector<float>& values, std::size_t from) {
  out += '[';
  for (std::size_t i = from; i < values.size(); ++i) {
    if (i > from) out += ',';
    fmt::format_to(std::back_inserter(out), "{:.5g}", values[i]);
  }
  out += ']';
}

}  // namespace

void LiveViewOptions::Check() const {
  if (port < 1 || port > 65535) {
    throw OptionError(fmt::format("--live-view: port {} is not in 1..65535", port));
  }
  if (host.empty()) throw OptionError("--live-view-host: empty");
  if (!(image_period_s > 0 && map_period_s > 0) || max_points == 0) {
    throw OptionError("live view: periods and the point budget must be positive");
  }
}

LiveView::LiveView(LiveViewOptions options)
    : options_(std::move(options)), server_(std::make_unique<httplib::Server>()) {
  options_.Check();
  page_ = LiveViewPage();
  server_->Get("/", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(page_, "text/html; charset=utf-8");
  });
  server_->Get("/data.json", [this](const httplib::Request& req, httplib::Response& res) {
    std::size_t since = 0;
    if (req.has_param("since")) {
      try {
        since = static_cast<std::size_t>(std::max(0L, std::stol(req.get_param_value("since"))));
      } catch (const std::exception&) {
        res.status = 400;
        res.set_content("since: not a number", "text/plain");
        return;
      }
    }
    res.set_header("Cache-Control", "no-store");
    res.set_content(DataJson(since), "application/json");
  });
  server_->Get("/frame.jpg", [this](const httplib::Request&, httplib::Response& res) {
    const std::vector<unsigned char> jpeg = FrameJpeg();
    if (jpeg.empty()) {
      res.status = 404;
      return;
    }
    res.set_header("Cache-Control", "no-store");
    res.set_content(reinterpret_cast<const char*>(jpeg.data()), jpeg.size(), "image/jpeg");
  });
  if (!server_->bind_to_port(options_.host, options_.port)) {
    throw Error(
        fmt::format("--live-view: cannot listen on {}:{} (in use, or not an address of "
                    "this machine); give another port",
                    options_.host, options_.port));
  }
  thread_ = std::thread([this] { server_->listen_after_bind(); });
  PKSLAM_LOG_INFO("live view: {}", url());
}

LiveView::~LiveView() {
  server_->stop();
  if (thread_.joinable()) thread_.join();
}

std::string LiveView::url() const {
  return fmt::format("http://{}:{}/", options_.host == "0.0.0.0" ? "localhost" : options_.host,
                     options_.port);
}

void LiveView::OnFrame(const SlamSystem& system, const TrackResult& result, const cv::Mat& image,
                       std::int64_t t_ns) {
  if (first_t_ns_ < 0) first_t_ns_ = t_ns;
  const double now = WallSeconds();
  const bool copy_image = now - last_image_s_ >= options_.image_period_s;
  std::vector<float> keypoints;
  cv::Mat image_copy;
  if (copy_image) {
    last_image_s_ = now;
    for (const auto& o : system.TrackedObservations()) {
      keypoints.push_back(o.u);
      keypoints.push_back(o.v);
    }
    image_copy = image.clone();
  }
  {
    MutexLock lock(mutex_);
    if (result.camera_from_world) {
      const Eigen::Vector3d c = result.camera_from_world->Inverse().translation();
      state_.positions.insert(
          state_.positions.end(),
          {static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())});
    }
    state_.frame += 1;
    state_.t_s = static_cast<double>(t_ns - first_t_ns_) * 1e-9;
    state_.state = std::string(TrackingStateName(result.state));
    state_.gravity_aligned = IsInertial(system.rig().sensor);
    if (copy_image) {
      state_.keypoints = std::move(keypoints);
      state_.image = std::move(image_copy);
      state_.image_seq += 1;
    }
  }
  if (now - last_map_s_ >= options_.map_period_s) {
    last_map_s_ = now;
    CopyMap(system);
  }
}

void LiveView::CopyMap(const SlamSystem& system) {
  // Read under the Atlas lock by SlamSystem, outside this view's mutex.
  const auto points = system.MapPoints();
  const auto keyframes = system.KeyFrames();
  const std::size_t stride = std::max<std::size_t>(1, points.size() / options_.max_points + 1);
  std::vector<float> flat_points;
  flat_points.reserve(3 * (points.size() / stride + 1));
  for (std::size_t i = 0; i < points.size(); i += stride) {
    for (int c = 0; c < 3; ++c)
      flat_points.push_back(static_cast<float>(points[i].world_position(c)));
  }
  std::vector<float> flat_keyframes;
  for (const auto& k : keyframes) {
    const Eigen::Vector3d p = k.world_from_camera.translation();
    const Eigen::Quaterniond q = k.world_from_camera.so3().quaternion();
    for (const double v : {p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w()}) {
      flat_keyframes.push_back(static_cast<float>(v));
    }
  }
  MutexLock lock(mutex_);
  state_.points = std::move(flat_points);
  state_.keyframes = std::move(flat_keyframes);
}

void LiveView::Finish(const SlamSystem* system) {
  if (system != nullptr) CopyMap(*system);
  MutexLock lock(mutex_);
  state_.finished = true;
}

std::string LiveView::DataJson(std::size_t since) const {
  MutexLock lock(mutex_);
  const State& s = state_;
  std::string out = fmt::format(
      "{{\"frame\":{},\"t_s\":{:.3f},\"state\":\"{}\",\"finished\":{},\"gravity_aligned\":{},"
      "\"image_seq\":{},\"pose_count\":{},\"poses\":",
      s.frame, s.t_s, s.state, s.finished, s.gravity_aligned, s.image_seq, s.positions.size() / 3);
  AppendNumbers(out, s.positions, std::min(3 * since, s.positions.size()));
  out += ",\"keyframes\":";
  AppendNumbers(out, s.keyframes, 0);
  out += ",\"points\":";
  AppendNumbers(out, s.points, 0);
  out += ",\"keypoints\":";
  AppendNumbers(out, s.keypoints, 0);
  out += "}";
  return out;
}

std::vector<unsigned char> LiveView::FrameJpeg() const {
  cv::Mat image;
  {
    MutexLock lock(mutex_);
    image = state_.image;  // shares the pixels; OnFrame replaces, never writes into, them
  }
  std::vector<unsigned char> jpeg;
  if (!image.empty()) cv::imencode(".jpg", image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 80});
  return jpeg;
}

}  // namespace pkslam::apps
