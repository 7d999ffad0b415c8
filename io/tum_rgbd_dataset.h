// TUM RGB-D dataset reader: ROOT/{rgb.txt, depth.txt[, groundtruth.txt]} ('#' comments,
// "timestamp filename" rows, timestamps in decimal seconds converted to int64 ns exactly).
// RGB and depth frames are associated one-to-one by nearest timestamp within a maximum
// difference, greedily by smallest difference (the convention of the benchmark's
// associate.py). Images load lazily; listed files that do not exist are reported and skipped.
// accelerometer.txt is ignored. Immutable after Open; safe to read from several threads.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <vector>

#include "core/geometry/se3.h"
#include "io/dataset_common.h"

namespace pkslam {

struct TumRgbdOptions {
  // Maximum |t_rgb - t_depth| for an association, seconds (associate.py's default).
  double max_difference_s = 0.02;
  // Depth PNG value per metre. 0 = RGBD.DepthMapFactor of ROOT/settings.yaml (an ORB-SLAM3
  // settings file) when that file exists and has the key, else 5000 (the TUM convention).
  double depth_factor = 0;
  // Nominal camera rate (the Kinect's), used for frame-gap detection.
  double nominal_rate_hz = 30;
  // An interval longer than this many nominal periods is reported as a frame gap.
  double frame_gap_periods = 1.5;

  void Check() const;
};

// A ground-truth row: "timestamp tx ty tz qx qy qz qw", the colour camera's optical centre in
// the motion-capture world frame.
struct TumGroundTruthPose {
  std::int64_t t_ns = 0;
  SE3d world_from_camera;
};

struct RgbdAssociation {
  std::size_t rgb = 0;    // index into rgb().images
  std::size_t depth = 0;  // index into depth().images
};

class TumRgbdDataset {
 public:
  // Throws InputError(file, line) on missing/empty/malformed lists or unsorted timestamps.
  static TumRgbdDataset Open(const std::filesystem::path& root, const TumRgbdOptions& options = {});
  static bool LooksLikeTumRgbd(const std::filesystem::path& root);

  const std::filesystem::path& root() const { return root_; }
  const ImageStream& rgb() const { return rgb_; }
  const ImageStream& depth() const { return depth_; }
  // Sorted by rgb timestamp.
  const std::vector<RgbdAssociation>& associations() const { return associations_; }
  bool has_ground_truth() const { return !ground_truth_.empty(); }
  const std::vector<TumGroundTruthPose>& ground_truth() const { return ground_truth_; }
  double depth_factor() const { return depth_factor_; }

  // Lazy loaders; throw InputError naming the file when it is missing or corrupt.
  cv::Mat LoadRgbColour(std::size_t rgb_index) const;   // CV_8UC3 BGR
  cv::Mat LoadRgbGrey(std::size_t rgb_index) const;     // CV_8UC1
  cv::Mat LoadDepthRaw(std::size_t depth_index) const;  // CV_16UC1 as stored
  // Throws InputError naming the first depth image when the first `images` associated depth
  // images hold no valid (non-zero) pixel: runs on an all-zero depth folder "tracked" with no
  // depth at all (an empty trajectory, identity poses evaluated as accurate).
  void RequireValidDepth(std::size_t images = 10) const;
  // The depth scale against the scene: the median valid depth of the first `images` associated
  // depth images, raw / `factor`, must lie within [0.1, 50] m (any room or street a depth camera
  // sees). Throws InputError naming the first depth image and `factor_source` otherwise:
  // RGBD.DepthMapFactor 1.0 on TUM data (5000 per metre) made every depth 5000x too far and
  // tracked each frame at 6.8 m ATE, exit 0.
  void CheckDepthScale(double factor, const std::string& factor_source,
                       std::size_t images = 10) const;
  // CV_32FC1 metres (raw / depth_factor); 0 stays 0 (no measurement).
  cv::Mat LoadDepthMetres(std::size_t depth_index) const;

 private:
  TumRgbdDataset() = default;

  std::filesystem::path root_;
  ImageStream rgb_;
  ImageStream depth_;
  std::vector<RgbdAssociation> associations_;
  std::vector<TumGroundTruthPose> ground_truth_;
  double depth_factor_ = 5000;
};

// rgb.txt / depth.txt: "timestamp filename" rows; paths resolved against the list's folder.
std::vector<ImageEntry> ReadTumImageList(const std::filesystem::path& list_file);
// groundtruth.txt: "timestamp tx ty tz qx qy qz qw".
std::vector<TumGroundTruthPose> ReadTumGroundTruth(const std::filesystem::path& file);

// One-to-one association of two increasing timestamp lists: candidate pairs with
// |a - b| < max_difference_ns, taken greedily by increasing difference (ties: earlier a, then
// earlier b). Result sorted by a. Each pair is (index into a, index into b).
std::vector<std::pair<std::size_t, std::size_t>> AssociateTimestamps(
    const std::vector<std::int64_t>& a_ns, const std::vector<std::int64_t>& b_ns,
    std::int64_t max_difference_ns);

}  // namespace pkslam
