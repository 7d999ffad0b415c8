// Writes a sequence in the TUM RGB-D benchmark layout:
//   DIR/rgb/<t>.png (8-bit colour), DIR/depth/<t>.png (uint16, metres * depth_factor,
//   0 = no measurement), DIR/rgb.txt, DIR/depth.txt, DIR/associations.txt (ORB-SLAM3's
//   rgbd_tum input), DIR/groundtruth.txt (`t tx ty tz qx qy qz qw`, world_from_rgb_camera).
// t is seconds with 6 decimals (TUM's convention); callers use microsecond-aligned times.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <string>
#include <utility>

#include "core/geometry/se3.h"

namespace pkslam::sim {

// "1305031102.175304" from 1305031102175304000 (the time must be a whole microsecond).
std::string TumTimestamp(std::int64_t t_ns);

class TumRgbdWriter {
 public:
  explicit TumRgbdWriter(const std::filesystem::path& dir);
  // colour: CV_8UC3 in RGB order; depth: CV_16U.
  void WriteFrame(std::int64_t t_ns, const cv::Mat& colour_rgb, const cv::Mat& depth);
  // The same in two steps (PNG encoding on another thread): AddFrame writes the list rows and
  // returns the colour and depth files for WriteImages (thread-safe, no shared state).
  std::pair<std::filesystem::path, std::filesystem::path> AddFrame(std::int64_t t_ns);
  static void WriteImages(const std::filesystem::path& colour_file,
                          const std::filesystem::path& depth_file, const cv::Mat& colour_rgb,
                          const cv::Mat& depth);
  void WriteGroundTruth(std::int64_t t_ns, const SE3d& world_from_camera);
  void Close();  // throws Error on a failed write
  ~TumRgbdWriter();

 private:
  std::filesystem::path dir_;
  std::ofstream rgb_txt_;
  std::ofstream depth_txt_;
  std::ofstream assoc_txt_;
  std::ofstream gt_txt_;
  bool closed_ = false;
};

}  // namespace pkslam::sim
