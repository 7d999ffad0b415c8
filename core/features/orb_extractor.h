// ORB feature extraction in the ORB-SLAM manner: scale pyramid, FAST per cell with threshold
// fallback, quadtree distribution with per-level quotas, intensity-centroid orientation and
// 256-bit rBRIEF on Gaussian-smoothed levels.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "core/features/descriptor.h"
#include "core/features/image_pyramid.h"
#include "core/features/orb_descriptor.h"

namespace pkslam {

struct OrbOptions {
  // Keypoints wanted over all levels (ORB-SLAM3 EuRoC: 1200 stereo, 1000 monocular).
  int n_features = 1200;
  // Scale between consecutive pyramid levels.
  double scale_factor = 1.2;
  // Number of pyramid levels.
  int n_levels = 8;
  // FAST threshold tried first in every cell.
  int ini_th_fast = 20;
  // FAST threshold for cells where the first one found nothing.
  int min_th_fast = 7;
  // No keypoint closer than this to a level's border (room for the patch and the tests).
  int edge_threshold = 19;
  // Side of the orientation disc and of the descriptor patch (31 = the published pattern).
  int patch_size = 31;
  // Nominal side of the FAST cells in pixels (cells are stretched to tile each level).
  int cell_size = 35;
  // Share the levels between the caller and one helper thread (ExtractStereo: one thread per
  // image); the output does not depend on it.
  bool parallel = true;

  void Check() const;
};

// Features of one image. Keypoints are grouped by octave (ascending); within an octave the
// order is deterministic.
struct OrbFeatures {
  // pt: level-0 pixels (exact pyramid mapping, see ImagePyramid); octave: pyramid level;
  // size: patch_size * scale^octave; angle: degrees in [0, 360), x right, y down;
  // response: FAST score.
  std::vector<cv::KeyPoint> keypoints;
  std::vector<Descriptor> descriptors;  // descriptors[i] belongs to keypoints[i]
  ImagePyramid pyramid;                 // unsmoothed levels, for stereo SAD refinement
  std::vector<cv::Mat> smoothed;        // Gaussian-smoothed levels the descriptors come from
};

// Immutable after construction; Extract* are const and keep no state between calls, so one
// extractor may be used from several threads at once (each call with its own output). With
// options.parallel a call starts one short-lived helper thread (two for ExtractStereo's pair)
// and joins it before returning; the output is written only by the call's threads.
class OrbExtractor {
 public:
  explicit OrbExtractor(const OrbOptions& options = {});

  const OrbOptions& options() const { return options_; }
  int NumLevels() const { return options_.n_levels; }
  // Per-level tables as the tracker uses them: scale = scale_factor^level, sigma2 = scale^2.
  const std::vector<float>& ScaleFactors() const { return scale_; }
  const std::vector<float>& InverseScaleFactors() const { return inv_scale_; }
  const std::vector<float>& LevelSigma2() const { return sigma2_; }
  const std::vector<float>& InverseLevelSigma2() const { return inv_sigma2_; }
  // Keypoint quota per level: n_features * (1 - f) / (1 - f^L) * f^level, f = 1/scale_factor
  // (ORB-SLAM's split), the last level taking the rounding remainder.
  const std::vector<int>& FeaturesPerLevel() const { return quota_; }

  // Extracts from a CV_8UC1 image, reusing `features`' buffers. `mask` (optional, CV_8UC1,
  // image size): keypoints only where it is non-zero.
  void Extract(const cv::Mat& image, OrbFeatures* features, const cv::Mat& mask = {}) const;
  OrbFeatures Extract(const cv::Mat& image) const;

  // Both images of a stereo pair concurrently.
  void ExtractStereo(const cv::Mat& left, const cv::Mat& right, OrbFeatures* left_features,
                     OrbFeatures* right_features) const;

 private:
  struct LevelResult {
    std::vector<cv::KeyPoint> keypoints;
    std::vector<Descriptor> descriptors;
  };

  void ExtractImpl(const cv::Mat& image, const cv::Mat& mask, bool with_helper,
                   OrbFeatures* features) const;
  void ExtractLevel(int level, const ImagePyramid& pyramid, const cv::Mat& mask, cv::Mat* smoothed,
                    LevelResult* out) const;
  std::vector<cv::KeyPoint> DetectCandidates(const cv::Mat& level_image, int level,
                                             const ImagePyramid& pyramid,
                                             const cv::Mat& mask) const;

  OrbOptions options_;
  std::vector<float> scale_, inv_scale_, sigma2_, inv_sigma2_;
  std::vector<int> quota_;
  OrientationDisc orientation_;
  RbriefPattern pattern_;
};

}  // namespace pkslam
