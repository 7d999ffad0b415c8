#include "core/bow/training_data.h"

#include <algorithm>
#include <cctype>
#include <exception>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "core/bow/parallel.h"
#include "core/features/orb_extractor.h"
#include "core/util/error.h"
#include "core/util/progress.h"

namespace pkslam {
namespace {

bool IsImageFile(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".pgm" || ext == ".ppm" ||
         ext == ".bmp" || ext == ".tif" || ext == ".tiff";
}

}  // namespace

void TrainingFeatureOptions::Check() const {
  PKSLAM_CHECK_OPTION(max_features >= 1, "max_features", "{}", max_features);
  PKSLAM_CHECK_OPTION(levels >= 1, "levels", "{}", levels);
  PKSLAM_CHECK_OPTION(scale_factor > 1.0, "scale_factor", "{}", scale_factor);
}

std::vector<Descriptor> ExtractTrainingDescriptors(const cv::Mat& gray,
                                                   const TrainingFeatureOptions& options) {
  PKSLAM_CHECK(gray.type() == CV_8UC1, "expected an 8-bit grey image, type {}", gray.type());
  OrbOptions orb;
  orb.n_features = options.max_features;
  orb.n_levels = options.levels;
  orb.scale_factor = options.scale_factor;
  orb.parallel = false;  // training already extracts one image per thread
  return OrbExtractor(orb).Extract(gray).descriptors;
}

std::vector<std::filesystem::path> ListTrainingImages(
    const std::vector<std::filesystem::path>& dirs, std::size_t max_images) {
  std::vector<std::filesystem::path> found;
  for (const auto& dir : dirs) {
    if (!std::filesystem::is_directory(dir)) throw InputError(dir, "not a directory");
    for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
      if (entry.is_regular_file() && IsImageFile(entry.path())) found.push_back(entry.path());
    }
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  if (found.empty()) {
    throw InputError(dirs.empty() ? std::filesystem::path() : dirs.front(),
                     "no image files (.png .jpg .pgm ...) found");
  }
  if (max_images == 0 || found.size() <= max_images) return found;
  std::vector<std::filesystem::path> subset;
  subset.reserve(max_images);
  for (std::size_t i = 0; i < max_images; ++i)
    subset.push_back(found[i * found.size() / max_images]);
  return subset;
}

std::vector<std::vector<Descriptor>> ExtractTrainingSet(
    const std::vector<std::filesystem::path>& images, const TrainingFeatureOptions& options,
    bool quiet, int threads) {
  options.Check();
  std::vector<std::vector<Descriptor>> out(images.size());
  // One slot per image, so the error reported (the first bad image in list order) does not
  // depend on scheduling.
  std::vector<std::exception_ptr> errors(images.size());
  std::mutex progress_mutex;  // Progress is single-threaded: serialise its updates
  Progress progress("vocab features", images.size(), quiet);
  bow_internal::ParallelFor(
      images.size(), bow_internal::ResolveThreadCount(threads), [&](std::size_t i) {
        try {
          const cv::Mat gray = cv::imread(images[i].string(), cv::IMREAD_GRAYSCALE);
          if (gray.empty()) throw InputError(images[i], "cannot read image");
          out[i] = ExtractTrainingDescriptors(gray, options);
        } catch (...) {
          errors[i] = std::current_exception();
        }
        std::lock_guard lock(progress_mutex);
        progress.Add();
      });
  progress.Finish();
  for (const auto& error : errors) {
    if (error) std::rethrow_exception(error);
  }
  return out;
}

}  // namespace pkslam
