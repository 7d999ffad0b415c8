// pkslam ORB vs OpenCV cv::ORB on the real EuRoC images (V1_01_easy_static, cam0, all 95) and
// on a synthetic textured image; stereo extraction and matching on a real pair.
//
// Time: wall-clock of the extraction call only (manual timing; both extractors may use both
// cores: pkslam through its level tasks, OpenCV through its own TBB-backed internals).
// Counters: median_ms = median per-image extraction time (wall); cpu_ms = median CPU time of
// the whole process (all threads) per extraction; features = mean keypoint count;
// spread_8x8grid = mean share of the 64 cells of an 8 x 8 grid laid over the image that hold
// a keypoint; spread_8px = mean share of the 8 x 8-pixel cells (94 x 60 for 752 x 480) that
// hold a keypoint.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "core/camera/stereo_rectification.h"
#include "core/camera/test_cameras.h"
#include "core/features/keypoint_spread.h"
#include "core/features/orb_extractor.h"
#include "core/features/stereo_matcher.h"
#include "core/features/synthetic_texture.h"
#include "core/util/cpu_time.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

constexpr int kFeatures = 1200;
constexpr int kLevels = 8;

std::filesystem::path EurocCamDir(const std::string& cam) {
  const auto shared = testing::SharedDataDir();
  if (!shared) return {};
  return *shared / "euroc" / "V1_01_easy_static" / "mav0" / cam / "data";
}

// The EuRoC images of one camera, sorted by name (= timestamp); empty when absent.
std::vector<std::filesystem::path> EurocFiles(const std::string& cam) {
  std::vector<std::filesystem::path> files;
  const std::filesystem::path dir = EurocCamDir(cam);
  if (dir.empty() || !std::filesystem::is_directory(dir)) return files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() == ".png") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<cv::Mat> LoadGrey(const std::vector<std::filesystem::path>& files) {
  std::vector<cv::Mat> images;
  images.reserve(files.size());
  for (const auto& f : files) images.push_back(cv::imread(f.string(), cv::IMREAD_GRAYSCALE));
  return images;
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Runs `extract(image) -> keypoints` cycling over `images`; times only the call.
template <typename Extract>
void RunExtraction(benchmark::State& state, const std::vector<cv::Mat>& images, Extract&& extract) {
  if (images.empty()) {
    state.SkipWithError("EuRoC images not found (../shared/data/euroc/V1_01_easy_static)");
    return;
  }
  std::vector<double> times_ms;
  std::vector<double> cpu_ms;
  double grid = 0.0;
  double px8 = 0.0;
  double count = 0.0;
  std::size_t i = 0;
  for (auto _ : state) {
    const cv::Mat& image = images[i % images.size()];
    const double c0 = ProcessCpuMs();
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<cv::KeyPoint> keypoints = extract(image);
    cpu_ms.push_back(ProcessCpuMs() - c0);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.SetIterationTime(seconds);
    times_ms.push_back(seconds * 1e3);
    grid += OccupiedGridShare(keypoints, image.size(), 8, 8);
    px8 += OccupiedPixelCellShare(keypoints, image.size(), 8);
    count += static_cast<double>(keypoints.size());
    ++i;
  }
  const double n = static_cast<double>(i);
  state.counters["median_ms"] = Median(times_ms);
  state.counters["cpu_ms"] = Median(cpu_ms);
  state.counters["features"] = count / n;
  state.counters["spread_8x8grid"] = grid / n;
  state.counters["spread_8px"] = px8 / n;
}

OrbOptions PkslamOptions(bool parallel) {
  OrbOptions options;
  options.n_features = kFeatures;
  options.n_levels = kLevels;
  options.scale_factor = 1.2;
  options.ini_th_fast = 20;
  options.parallel = parallel;
  return options;
}

cv::Ptr<cv::ORB> OpenCvOrb() {
  return cv::ORB::create(kFeatures, 1.2f, kLevels, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31, 20);
}

void RunPkslam(benchmark::State& state, const std::vector<cv::Mat>& images, bool parallel) {
  const OrbExtractor extractor(PkslamOptions(parallel));
  OrbFeatures features;
  RunExtraction(state, images, [&](const cv::Mat& image) {
    extractor.Extract(image, &features);
    return features.keypoints;
  });
}

void RunOpenCv(benchmark::State& state, const std::vector<cv::Mat>& images) {
  const cv::Ptr<cv::ORB> orb = OpenCvOrb();
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  RunExtraction(state, images, [&](const cv::Mat& image) {
    orb->detectAndCompute(image, cv::noArray(), keypoints, descriptors);
    return keypoints;
  });
}

std::vector<cv::Mat> SyntheticImages() { return {SyntheticTexture(cv::Size(752, 480), 7)}; }

void BM_PkslamOrb_Euroc(benchmark::State& state) {
  RunPkslam(state, LoadGrey(EurocFiles("cam0")), true);
}
void BM_PkslamOrbSequential_Euroc(benchmark::State& state) {
  RunPkslam(state, LoadGrey(EurocFiles("cam0")), false);
}
void BM_OpenCvOrb_Euroc(benchmark::State& state) { RunOpenCv(state, LoadGrey(EurocFiles("cam0"))); }
void BM_PkslamOrb_Synthetic(benchmark::State& state) { RunPkslam(state, SyntheticImages(), true); }
void BM_PkslamOrbSequential_Synthetic(benchmark::State& state) {
  RunPkslam(state, SyntheticImages(), false);
}
void BM_OpenCvOrb_Synthetic(benchmark::State& state) { RunOpenCv(state, SyntheticImages()); }

// pkslam and cv::ORB alternating on the same image, so that both see the same machine load
// (this machine is shared): medians of each and of the per-image time ratio.
void BM_PairedPkslamVsOpenCv_Euroc(benchmark::State& state) {
  const std::vector<cv::Mat> images = LoadGrey(EurocFiles("cam0"));
  if (images.empty()) {
    state.SkipWithError("EuRoC images not found (../shared/data/euroc/V1_01_easy_static)");
    return;
  }
  const OrbExtractor extractor(PkslamOptions(true));
  const cv::Ptr<cv::ORB> orb = OpenCvOrb();
  OrbFeatures features;
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  std::vector<double> ours, theirs, ratio;
  std::size_t i = 0;
  for (auto _ : state) {
    const cv::Mat& image = images[i % images.size()];
    double t_ours = 0.0;
    double t_theirs = 0.0;
    for (int k = 0; k < 2; ++k) {
      const bool ours_now = (k == 0) == (i % 2 == 0);  // alternate who goes first
      const auto t0 = std::chrono::steady_clock::now();
      if (ours_now) {
        extractor.Extract(image, &features);
      } else {
        orb->detectAndCompute(image, cv::noArray(), keypoints, descriptors);
      }
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      (ours_now ? t_ours : t_theirs) = ms;
    }
    state.SetIterationTime((t_ours + t_theirs) * 1e-3);
    ours.push_back(t_ours);
    theirs.push_back(t_theirs);
    ratio.push_back(t_ours / t_theirs);
    ++i;
  }
  state.counters["pkslam_median_ms"] = Median(ours);
  state.counters["opencv_median_ms"] = Median(theirs);
  state.counters["median_ratio"] = Median(ratio);
}

// First stereo pair present in both cameras (cam1 lacks a few frames).
bool LoadEurocPair(cv::Mat* left, cv::Mat* right) {
  for (const auto& f : EurocFiles("cam0")) {
    const auto other = EurocCamDir("cam1") / f.filename();
    if (std::filesystem::exists(other)) {
      *left = cv::imread(f.string(), cv::IMREAD_GRAYSCALE);
      *right = cv::imread(other.string(), cv::IMREAD_GRAYSCALE);
      return !left->empty() && !right->empty();
    }
  }
  return false;
}

// ExtractStereo (both images concurrently) vs two Extract calls one after the other.
void BM_PkslamOrbStereo_Euroc(benchmark::State& state) {
  const bool concurrent = state.range(0) != 0;
  cv::Mat left, right;
  if (!LoadEurocPair(&left, &right)) {
    state.SkipWithError("EuRoC stereo pair not found (../shared/data/euroc/V1_01_easy_static)");
    return;
  }
  const OrbExtractor extractor(PkslamOptions(true));
  OrbFeatures fl, fr;
  std::vector<double> times_ms;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    if (concurrent) {
      extractor.ExtractStereo(left, right, &fl, &fr);
    } else {
      extractor.Extract(left, &fl);
      extractor.Extract(right, &fr);
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.SetIterationTime(seconds);
    times_ms.push_back(seconds * 1e3);
  }
  state.counters["median_ms"] = Median(times_ms);
  state.counters["features"] = static_cast<double>(fl.keypoints.size() + fr.keypoints.size());
}

// Stereo matching alone on the real pair, rectified with the EuRoC calibration.
void BM_StereoMatch_Euroc(benchmark::State& state) {
  cv::Mat raw_left, raw_right;
  if (!LoadEurocPair(&raw_left, &raw_right)) {
    state.SkipWithError("EuRoC stereo pair not found (../shared/data/euroc/V1_01_easy_static)");
    return;
  }
  const StereoRectification rectification(testing::EurocCam0(), testing::EurocCam1(),
                                          testing::EurocCam1FromCam0());
  const auto [left, right] = rectification.Rectify(raw_left, raw_right);
  const OrbExtractor extractor(PkslamOptions(true));
  OrbFeatures fl, fr;
  extractor.ExtractStereo(left, right, &fl, &fr);
  StereoMatches matches;
  for (auto _ : state) {
    matches = MatchStereo(fl, fr, rectification.bf(), rectification.rectified_camera().fx());
    benchmark::DoNotOptimize(matches.num_matches);
  }
  std::vector<double> depths;
  for (float d : matches.depth) {
    if (d > 0.0f) depths.push_back(d);
  }
  state.counters["matches"] = matches.num_matches;
  state.counters["left_keypoints"] = static_cast<double>(fl.keypoints.size());
  state.counters["median_depth_m"] = depths.empty() ? 0.0 : Median(depths);
}

BENCHMARK(BM_PkslamOrb_Euroc)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(285);
BENCHMARK(BM_PkslamOrbSequential_Euroc)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(285);
BENCHMARK(BM_OpenCvOrb_Euroc)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(285);
BENCHMARK(BM_PairedPkslamVsOpenCv_Euroc)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(285);
BENCHMARK(BM_PkslamOrb_Synthetic)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PkslamOrbSequential_Synthetic)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OpenCvOrb_Synthetic)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PkslamOrbStereo_Euroc)
    ->ArgName("concurrent")
    ->Arg(1)
    ->Arg(0)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StereoMatch_Euroc)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pkslam
