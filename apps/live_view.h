// `pkslam run --live-view [PORT]`: while a run goes, a small HTTP server (Debian's cpp-httplib)
// serves the viewer's live page (viewer/viewer_live.js) and what it draws: the camera path so
// far, the keyframes and map points of the largest map, the current left image and its tracked
// keypoints. The run's tracking thread copies that into the view after each frame (OnFrame:
// poses every frame, the image and keypoints at most every image_period_s, the map at most
// every map_period_s); the server's threads only read those copies under the mutex, never the
// map. Without --live-view nothing of this runs.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <thread>
#include <vector>

#include "core/util/annotated_mutex.h"
#include "system/slam_system.h"

namespace httplib {
class Server;
}

namespace pkslam::apps {

struct LiveViewOptions {
  std::string host = "127.0.0.1";  // 0.0.0.0 to be seen from other machines
  int port = 8765;
  double image_period_s = 0.2;     // the current image is copied at most this often
  double map_period_s = 1.0;       // the map's points and keyframes at most this often
  std::size_t max_points = 60000;  // map points sent (every k-th beyond)

  void Check() const;  // throws OptionError
};

class LiveView {
 public:
  // Starts the server (throws Error when the port cannot be bound: naming host and port).
  explicit LiveView(LiveViewOptions options);
  ~LiveView();  // stops the server
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  // The run's tracking thread, after each frame.
  void OnFrame(const SlamSystem& system, const TrackResult& result, const cv::Mat& image,
               std::int64_t t_ns);
  // The run has stopped tracking: the map copied once more, the page told so.
  void Finish(const SlamSystem* system);
  std::string url() const;

 private:
  struct State {
    std::vector<float> positions;  // camera centres, x y z per tracked frame
    std::vector<float> keyframes;  // x y z qx qy qz qw per keyframe
    std::vector<float> points;     // x y z per (sent) map point
    std::vector<float> keypoints;  // u v per tracked keypoint of the current image
    cv::Mat image;                 // the current left image (grey or colour)
    int image_seq = 0;
    int frame = 0;
    double t_s = 0;
    std::string state = "NOT_INITIALIZED";
    bool gravity_aligned = false;
    bool finished = false;
  };
  void CopyMap(const SlamSystem& system);
  std::string DataJson(std::size_t since) const;
  std::vector<unsigned char> FrameJpeg() const;

  LiveViewOptions options_;
  std::string page_;
  // Tracking thread only: when the image and the map were last copied, and the first stamp.
  double last_image_s_ = -1e9;
  double last_map_s_ = -1e9;
  std::int64_t first_t_ns_ = -1;

  mutable Mutex mutex_;
  State state_ PKSLAM_GUARDED_BY(mutex_);

  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
};

}  // namespace pkslam::apps
