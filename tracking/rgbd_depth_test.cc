// RGB-D depth in pose optimisation: the depth reading's own noise (core/sensor/
// depth_uncertainty.h) weights a disparity residual, instead of the keypoint's pixel sigma on
// a virtual right coordinate (ORB-SLAM's form, kept for stereo).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"
#include "tracking/pose_optimizer.h"

namespace pkslam {
namespace {

constexpr double kKinectK = 1.425e-3;

std::shared_ptr<CameraRig> MakeRgbdRig() {
  auto rig = testing::MakeStereoRig(Sensor::kRgbd);
  rig->baseline = 0.07;  // TUM-like virtual baseline
  rig->bf = rig->fx * rig->baseline;
  rig->th_depth = 40 * rig->baseline;
  return rig;
}

struct RgbdFrame {
  Frame frame;
  SE3d truth;
};

// A frame at `truth` seeing points 1-4 m away, with 1 px keypoint noise and Kinect depth
// noise; matched to map points at their true positions and posed 5 cm / 2 degrees off.
// with_sigma = false leaves the depth sigmas out (the stereo-style residual).
// depth_error_m is added to the depth of every 10th keypoint.
RgbdFrame MakeRgbdFrame(std::uint64_t seed, bool with_sigma, double depth_error_m = 0.0) {
  const std::shared_ptr<CameraRig> rig = MakeRgbdRig();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  RgbdFrame out;
  out.truth = SE3d::Exp((Eigen::Matrix<double, 6, 1>() << 0.1 * uni(rng), 0.1 * uni(rng),
                         0.1 * uni(rng), 0.05 * uni(rng), 0.05 * uni(rng), 0.05 * uni(rng))
                            .finished());
  FrameFeatures f;
  std::vector<Eigen::Vector3d> points;
  while (points.size() < 250) {
    const double z = 1.0 + 1.5 * (uni(rng) + 1.0);
    const Eigen::Vector3d pc(z * 0.8 * uni(rng), z * 0.5 * uni(rng), z);
    const auto uv = rig->camera.Project(pc);
    if (!uv || !rig->bounds.Contains(uv->x(), uv->y())) continue;
    cv::KeyPoint kp(static_cast<float>(uv->x() + gauss(rng)),
                    static_cast<float>(uv->y() + gauss(rng)), 31.0f);
    kp.octave = 0;
    f.keypoints.push_back(kp);
    f.descriptors.emplace_back();
    const double sigma = kKinectK * z * z;
    double depth = z + sigma * gauss(rng);
    if (points.size() % 10 == 0) depth += depth_error_m;
    f.depth.push_back(static_cast<float>(depth));
    if (with_sigma) f.depth_sigma.push_back(static_cast<float>(sigma));
    points.push_back(out.truth.Inverse() * pc);
  }
  out.frame = Frame(1, 0, rig, std::move(f));
  for (int i = 0; i < out.frame.size(); ++i) {
    out.frame.map_points[i] = std::make_shared<MapPoint>(i, points[i], nullptr, nullptr);
  }
  const Eigen::Matrix<double, 6, 1> delta =
      (Eigen::Matrix<double, 6, 1>() << 0.03, -0.03, 0.03, 0.02, -0.02, 0.01).finished();
  out.frame.SetPose(SE3d::Exp(delta) * out.truth);
  return out;
}

double TranslationError(const RgbdFrame& f) {
  return (f.frame.CameraCenter() - f.truth.Inverse().translation()).norm();
}

TEST(RgbdDepth, FrameDerivesDisparityInformationFromDepthSigma) {
  RgbdFrame f = MakeRgbdFrame(1, true);
  const CameraRig& rig = f.frame.rig();
  for (int i = 0; i < f.frame.size(); ++i) {
    ASSERT_TRUE(f.frame.HasDepth(i));
    // Quadratic noise is constant in disparity: 1 / (bf k)^2 whatever the depth.
    const double z = f.frame.depth()[i];
    const double expected = std::pow(rig.bf * f.frame.depth_sigma()[i] / (z * z), -2);
    EXPECT_NEAR(f.frame.DisparityInformation(i), expected, 1e-6 * expected);
  }
  EXPECT_EQ(MakeRgbdFrame(1, false).frame.DisparityInformation(0), 0.0);
}

TEST(RgbdDepth, WrongDepthReadingsAreOutliers) {
  // 15 cm off at 1-4 m: 0.3-4.6 px of disparity, mostly within the pixel-sigma gate on the
  // right coordinate, all far outside the depth noise (bf k = 0.04 px).
  RgbdFrame weighted = MakeRgbdFrame(7, true, 0.15);
  RgbdFrame pixel = MakeRgbdFrame(7, false, 0.15);
  OptimizePose(&weighted.frame);
  OptimizePose(&pixel.frame);
  int flagged_weighted = 0, flagged_pixel = 0, wrong = 0;
  for (int i = 0; i < weighted.frame.size(); ++i) {
    if (i % 10 != 0) continue;
    ++wrong;
    flagged_weighted += weighted.frame.outliers[i];
    flagged_pixel += pixel.frame.outliers[i];
  }
  EXPECT_EQ(flagged_weighted, wrong);
  EXPECT_LT(flagged_pixel, wrong / 2);
  EXPECT_LT(TranslationError(weighted), 5e-3);
}

}  // namespace
}  // namespace pkslam
