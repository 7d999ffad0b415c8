// Place-recognition sanity check on real photographs: a vocabulary trained on some images
// must recognise a perturbed copy (noise, small shift, brightness change) of any image, seen
// in training or not, as closest to its source.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/bow/training_data.h"
#include "core/bow/vocabulary.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

const fs::path kOpenCvData = "/usr/share/doc/opencv-doc/examples/data";

// Distinct scenes (no stereo or sequence partners of each other).
const char* const kPhotos[] = {
    "baboon.jpg", "building.jpg", "butterfly.jpg",    "fruits.jpg",       "home.jpg",
    "messi5.jpg", "orange.jpg",   "smarties.png",     "starry_night.jpg", "stuff.jpg",
    "sudoku.png", "board.jpg",    "HappyFish.jpg",    "apple.jpg",        "aero1.jpg",
    "blox.jpg",   "cards.png",    "squirrel_cls.jpg", "graf1.png",        "leuvenA.jpg",
    "left01.jpg", "aloeL.jpg",    "basketball1.png",  "pic1.png"};

cv::Mat Perturb(const cv::Mat& gray, int seed) {
  cv::Mat shifted;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 3, 0, 1, -2);
  cv::warpAffine(gray, shifted, shift, gray.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  cv::Mat noise(gray.size(), CV_16SC1);
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  rng.fill(noise, cv::RNG::NORMAL, 0, 6);
  cv::Mat out;
  shifted.convertTo(out, CV_16SC1, 1.0, 10.0);
  out += noise;
  out.convertTo(out, CV_8UC1);  // saturates
  return out;
}

TEST(PlaceRecognition, PerturbedCopyScoresHighestWithItsSource) {
  std::vector<cv::Mat> images;
  std::vector<std::string> names;
  for (const char* name : kPhotos) {
    cv::Mat gray = cv::imread((kOpenCvData / name).string(), cv::IMREAD_GRAYSCALE);
    if (gray.empty()) continue;
    images.push_back(gray);
    names.push_back(name);
  }
  if (images.size() < 12) GTEST_SKIP() << "opencv-doc example photos not found in " << kOpenCvData;

  TrainingFeatureOptions features;
  features.max_features = 1000;
  std::vector<std::vector<Descriptor>> descriptors;
  for (const cv::Mat& image : images) {
    descriptors.push_back(ExtractTrainingDescriptors(image, features));
  }
  // Train on the first two thirds; the rest are images the vocabulary has never seen.
  const std::size_t n_train = images.size() * 2 / 3;
  VocabularyTrainOptions options;
  options.branching = 10;
  options.levels = 4;
  options.quiet = true;
  const Vocabulary vocabulary =
      Vocabulary::Train(std::vector<std::vector<Descriptor>>(
                            descriptors.begin(), descriptors.begin() + static_cast<long>(n_train)),
                        options);

  std::vector<BowVector> sources;
  for (const auto& d : descriptors) sources.push_back(vocabulary.Transform(d));
  for (std::size_t i = 0; i < images.size(); ++i) {
    const BowVector query = vocabulary.Transform(
        ExtractTrainingDescriptors(Perturb(images[i], 100 + static_cast<int>(i)), features));
    EXPECT_NEAR(vocabulary.Score(sources[i], sources[i]), 1.0, 1e-12);
    const double own = vocabulary.Score(query, sources[i]);
    double best_other = 0.0;
    std::string best_other_name;
    for (std::size_t j = 0; j < images.size(); ++j) {
      if (j == i) continue;
      const double s = vocabulary.Score(query, sources[j]);
      if (s > best_other) {
        best_other = s;
        best_other_name = names[j];
      }
    }
    EXPECT_GT(own, best_other) << names[i] << (i < n_train ? " (trained)" : " (unseen)") << " vs "
                               << best_other_name;
    RecordProperty(names[i], std::to_string(own) + " vs " + std::to_string(best_other));
  }
}

}  // namespace
}  // namespace pkslam
