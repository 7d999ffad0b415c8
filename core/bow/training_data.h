// Training material for vocabularies: finding images and extracting their ORB descriptors.
#pragma once

#include <cstddef>
#include <filesystem>
#include <opencv2/core.hpp>
#include <vector>

#include "core/features/descriptor.h"

namespace pkslam {

struct TrainingFeatureOptions {
  // Keypoints per image (ORB-SLAM3 uses 1000-1200).
  int max_features = 1000;
  // Pyramid levels and scale step of the extractor.
  int levels = 8;
  double scale_factor = 1.2;

  void Check() const;
};

// ORB descriptors of one 8-bit grey image, as the vocabulary will later see them: pkslam's
// OrbExtractor (ORB-SLAM's quadtree-distributed ORB), the extractor tracking uses.
std::vector<Descriptor> ExtractTrainingDescriptors(const cv::Mat& gray,
                                                   const TrainingFeatureOptions& options);

// Image files (.png .jpg .jpeg .pgm .ppm .bmp .tif .tiff, any case) found recursively under
// `dirs`, sorted by path. If max_images > 0 and more were found, an evenly spaced subset of
// that many (deterministic). InputError if a directory is missing or no image is found.
std::vector<std::filesystem::path> ListTrainingImages(
    const std::vector<std::filesystem::path>& dirs, std::size_t max_images);

// Loads each image as grey and extracts its descriptors on `threads` threads (0 = one per
// hardware thread), with a progress bar. Result i belongs to images[i]. InputError naming the
// file for an unreadable image (the first in list order).
std::vector<std::vector<Descriptor>> ExtractTrainingSet(
    const std::vector<std::filesystem::path>& images, const TrainingFeatureOptions& options,
    bool quiet, int threads = 0);

}  // namespace pkslam
