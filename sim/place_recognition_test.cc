// Place recognition with the shipped vocabulary on a simulated flight that revisits places
// (issue 4): a 30 s random medium flight through the Vicon-like room is flown twice; the second
// lap is offset from the first (0.3 m sideways, 8 degrees of rotation, a quarter second along
// the path, other sensor noise and gain), as a real second lap would be. Keyframes every 0.5 s
// of the first lap; for >= 90% of the second lap's frames the best BoW match among them must
// show the same place (camera within 1 m, viewing directions within 30 degrees).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <vector>

#include "core/bow/vocabulary.h"
#include "core/features/orb_extractor.h"
#include "sim/euroc_writer.h"
#include "sim/motion_generator.h"
#include "sim/renderer.h"
#include "sim/scene_builder.h"
#include "sim/scene_description.h"
#include "sim/sensor_model.h"

namespace pkslam::sim {
namespace {

constexpr std::int64_t kSecond = 1'000'000'000;

struct View {
  double t_s = 0.0;
  SE3d world_from_camera;
  BowVector bow;
};

bool SamePlace(const SE3d& a, const SE3d& b, double max_distance_m, double max_angle_deg) {
  const Eigen::Vector3d za = a.RotationMatrix().col(2);
  const Eigen::Vector3d zb = b.RotationMatrix().col(2);
  const double angle = std::acos(std::clamp(za.dot(zb), -1.0, 1.0)) * 180.0 / M_PI;
  return (a.translation() - b.translation()).norm() <= max_distance_m && angle <= max_angle_deg;
}

TEST(PlaceRecognition, BestBowMatchOfARevisitIsAKeyframeOfThatPlace) {
  const std::filesystem::path vocabulary_file =
      std::filesystem::path(PKSLAM_SOURCE_DIR) / "Vocabulary/pkslam_orb_k10_L6.bin";
  if (!std::filesystem::exists(vocabulary_file)) GTEST_SKIP() << "no shipped vocabulary";
  const Vocabulary vocabulary = Vocabulary::Load(vocabulary_file);

  SceneBuildOptions build;
  build.texture_size = 512;
  build.seed = 21;
  const Scene scene = BuildScene(LoadSceneDescription("vicon_room"), build, {});
  const CameraRig cam0 = EurocCam0();
  MotionOptions motion;
  motion.duration_s = 30.0;
  const SplineTrajectory flight = GenerateMotion(scene, motion, cam0.body_from_camera, 21, 0);

  const CameraRays rays(cam0.camera);
  const Renderer renderer(scene, RenderOptions());
  SensorModel sensor(SensorOptions(), rays, 21);
  const OrbExtractor extractor;
  auto make_view = [&](std::int64_t t_ns, std::uint64_t noise_key, const SE3d& offset) {
    View v;
    v.t_s = static_cast<double>(t_ns) / kSecond;
    v.world_from_camera = flight.WorldFromBody(t_ns) * cam0.body_from_camera * offset;
    RenderBuffers buffers;
    renderer.Render(rays, v.world_from_camera, &buffers);
    const cv::Mat image =
        sensor.Develop(buffers.radiance, sensor.NextGain(buffers.radiance, 0.05), noise_key);
    OrbFeatures features;
    extractor.Extract(image, &features);
    v.bow = vocabulary.Transform(features.descriptors);
    return v;
  };

  // Keyframes every 0.5 s of the first lap from the end of the initial rest; the second lap's
  // frames sit between them along the path (never an exact keyframe pose).
  const std::int64_t begin = flight.begin_ns() + 2 * kSecond;
  const std::int64_t end = flight.end_ns() - kSecond / 10;
  std::vector<View> keyframes;
  std::uint64_t key = 1;
  for (std::int64_t t = begin; t < end; t += kSecond / 2) keyframes.push_back(make_view(t, ++key, SE3d()));

  int revisits = 0;
  int correct = 0;
  std::mt19937 rng(5);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (std::int64_t t = begin + kSecond / 4; t < end; t += kSecond / 2) {
    // The second lap: the same place, seen from a pose offset by 0.3 m and 8 degrees.
    const Eigen::Vector3d axis = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    const Eigen::Vector3d shift = Eigen::Vector3d(gauss(rng), gauss(rng), 0.2 * gauss(rng));
    const SE3d offset(SO3d::Exp(axis * 8.0 * M_PI / 180.0), 0.3 * shift.normalized());
    ++revisits;
    const View query = make_view(t, ++key, offset);
    const View* best = nullptr;
    double best_score = -1.0;
    for (const View& k : keyframes) {
      const double s = vocabulary.Score(query.bow, k.bow);
      if (s > best_score) {
        best_score = s;
        best = &k;
      }
    }
    ASSERT_NE(best, nullptr);
    if (SamePlace(best->world_from_camera, query.world_from_camera, 1.0, 30.0)) ++correct;
  }
  std::printf("place recognition: %d of %d revisits (%.1f%%) matched a keyframe of that place\n",
              correct, revisits, revisits ? 100.0 * correct / revisits : 0.0);
  ASSERT_GE(revisits, 40);
  EXPECT_GE(correct, 0.9 * revisits);
}

}  // namespace
}  // namespace pkslam::sim
