// Camera model speed: per-keypoint undistortion (ours vs cv::undistortPoints), projection with
// and without Jacobian, unprojection, and stereo image rectification at EuRoC size.
#include <benchmark/benchmark.h>

#include <opencv2/calib3d.hpp>
#include <random>

#include "core/camera/camera_model.h"
#include "core/camera/stereo_rectification.h"
#include "core/camera/test_cameras.h"

namespace pkslam {
namespace {

constexpr int kKeypoints = 2000;

// Uniformly spread keypoints over the image, like an ORB extractor's output.
std::vector<cv::Point2f> RandomKeypoints(const CameraModel& cam, int n) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.f, static_cast<float>(cam.width() - 1));
  std::uniform_real_distribution<float> v(0.f, static_cast<float>(cam.height() - 1));
  std::vector<cv::Point2f> points(n);
  for (auto& p : points) p = {u(rng), v(rng)};
  return points;
}

void BM_UndistortPixels_Pkslam(benchmark::State& state) {
  const CameraModel cam = testing::EurocCam0();
  const std::vector<cv::Point2f> in = RandomKeypoints(cam, kKeypoints);
  std::vector<cv::Point2f> out;
  for (auto _ : state) {
    cam.UndistortPixels(in, &out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * kKeypoints);
}
BENCHMARK(BM_UndistortPixels_Pkslam);

// What ORB-SLAM does: OpenCV's default 5 fixed-point iterations (inexact at the corners).
void BM_UndistortPoints_OpenCvDefault(benchmark::State& state) {
  const CameraModel cam = testing::EurocCam0();
  const std::vector<cv::Point2f> in = RandomKeypoints(cam, kKeypoints);
  const cv::Mat k = cam.CvK(), d = cam.CvDistortion();
  std::vector<cv::Point2f> out;
  for (auto _ : state) {
    cv::undistortPoints(in, out, k, d, cv::noArray(), k);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * kKeypoints);
}
BENCHMARK(BM_UndistortPoints_OpenCvDefault);

// OpenCV run until it matches our accuracy (< 1e-6 px needs ~50 iterations at the corners).
void BM_UndistortPoints_OpenCv50Iterations(benchmark::State& state) {
  const CameraModel cam = testing::EurocCam0();
  const std::vector<cv::Point2f> in = RandomKeypoints(cam, kKeypoints);
  const cv::Mat k = cam.CvK(), d = cam.CvDistortion();
  std::vector<cv::Point2f> out;
  for (auto _ : state) {
    cv::undistortPoints(in, out, k, d, cv::noArray(), k,
                        cv::TermCriteria(cv::TermCriteria::COUNT, 50, 0));
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * kKeypoints);
}
BENCHMARK(BM_UndistortPoints_OpenCv50Iterations);

void BM_Project(benchmark::State& state, const CameraModel& cam, bool with_jacobian) {
  std::vector<Eigen::Vector3d> points;
  for (const cv::Point2f& p : RandomKeypoints(cam, kKeypoints)) {
    points.push_back(3.0 * cam.Unproject(Eigen::Vector2d(p.x, p.y)));
  }
  Eigen::Matrix<double, 2, 3> jac;
  for (auto _ : state) {
    for (const Eigen::Vector3d& p : points) {
      benchmark::DoNotOptimize(cam.Project(p, with_jacobian ? &jac : nullptr));
    }
  }
  state.SetItemsProcessed(state.iterations() * kKeypoints);
}
BENCHMARK_CAPTURE(BM_Project, euroc, testing::EurocCam0(), false);
BENCHMARK_CAPTURE(BM_Project, euroc_jacobian, testing::EurocCam0(), true);
BENCHMARK_CAPTURE(BM_Project, kb8, testing::TumViKb8(), false);
BENCHMARK_CAPTURE(BM_Project, kb8_jacobian, testing::TumViKb8(), true);

void BM_Unproject(benchmark::State& state, const CameraModel& cam) {
  const std::vector<cv::Point2f> in = RandomKeypoints(cam, kKeypoints);
  for (auto _ : state) {
    for (const cv::Point2f& p : in) {
      benchmark::DoNotOptimize(cam.Unproject(Eigen::Vector2d(p.x, p.y)));
    }
  }
  state.SetItemsProcessed(state.iterations() * kKeypoints);
}
BENCHMARK_CAPTURE(BM_Unproject, euroc, testing::EurocCam0());
BENCHMARK_CAPTURE(BM_Unproject, kb8, testing::TumViKb8());

void BM_RectifyStereoPair(benchmark::State& state) {
  const StereoRectification rect(testing::EurocCam0(), testing::EurocCam1(),
                                 testing::EurocCam1FromCam0());
  cv::Mat left(480, 752, CV_8UC1), right(480, 752, CV_8UC1);
  cv::randu(left, 0, 255);
  cv::randu(right, 0, 255);
  for (auto _ : state) benchmark::DoNotOptimize(rect.Rectify(left, right));
}
BENCHMARK(BM_RectifyStereoPair)->Unit(benchmark::kMicrosecond);

void BM_RectifyKeypoints(benchmark::State& state) {
  const StereoRectification rect(testing::EurocCam0(), testing::EurocCam1(),
                                 testing::EurocCam1FromCam0());
  const std::vector<cv::Point2f> in = RandomKeypoints(testing::EurocCam0(), kKeypoints);
  for (auto _ : state) {
    for (const cv::Point2f& p : in) {
      benchmark::DoNotOptimize(rect.RectifyLeftPixel(Eigen::Vector2d(p.x, p.y)));
    }
  }
  state.SetItemsProcessed(state.iterations() * kKeypoints);
}
BENCHMARK(BM_RectifyKeypoints);

}  // namespace
}  // namespace pkslam
