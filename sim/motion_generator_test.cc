#include "sim/motion_generator.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sim/euroc_writer.h"
#include "sim/scene_builder.h"

namespace pkslam::sim {
namespace {

Scene TinyScene(const std::string& name) {
  SceneBuildOptions o;
  o.texture_size = 16;  // geometry matters here, not texture detail
  return BuildScene(LoadSceneDescription(name), o, {});
}

struct Stats {
  double mean_speed = 0;
  double mean_rate_dps = 0;
  double min_clearance = 1e9;
  double min_view = 1e9;
  double max_view = 0;
  double start_speed = 0;
  double rms_jerk = 0;
};

Stats Measure(const Scene& scene, const SplineTrajectory& traj, const SE3d& body_from_camera,
              double rest_s) {
  Stats s;
  int n = 0;
  int n_view = 0;
  double view_sum = 0;
  const std::int64_t step = 50'000'000;
  const std::int64_t moving = traj.begin_ns() + static_cast<std::int64_t>(rest_s * 1e9);
  for (std::int64_t t = traj.begin_ns(); t <= traj.end_ns(); t += step) {
    const BodyState st = traj.State(t);
    if (t < moving) {
      s.start_speed = std::max(s.start_speed, st.velocity_world.norm());
      continue;
    }
    s.mean_speed += st.velocity_world.norm();
    Eigen::Vector3d jerk;
    traj.position().Evaluate(t, nullptr, nullptr, &jerk);
    s.rms_jerk += jerk.squaredNorm();
    s.mean_rate_dps += st.omega_body.norm() * 180 / M_PI;
    ++n;
    const SE3d cam = st.world_from_body * body_from_camera;
    const Eigen::Vector3f p = cam.translation().cast<float>();
    s.min_clearance = std::min<double>(s.min_clearance, scene.ObjectClearance(p));
    Hit hit;
    const Eigen::Vector3f axis = cam.so3().Matrix().col(2).cast<float>();
    if (scene.Intersect(p, axis, 1e3f, &hit)) {
      view_sum += hit.t;
      ++n_view;
      s.min_view = std::min<double>(s.min_view, hit.t);
      s.max_view = std::max<double>(s.max_view, hit.t);
    }
  }
  s.mean_speed /= n;
  s.mean_rate_dps /= n;
  s.rms_jerk = std::sqrt(s.rms_jerk / n);
  return s;
}

TEST(MotionGenerator, LevelsHitTheirSpeedAndRateTargetsAndStayClear) {
  const Scene scene = TinyScene("vicon_room");
  const SE3d body_from_camera = EurocCam0().body_from_camera;
  double previous_jerk = 0.0;
  for (MotionLevel level : {MotionLevel::kEasy, MotionLevel::kMedium, MotionLevel::kDifficult}) {
    MotionOptions o;
    o.level = level;
    o.duration_s = 60;
    const SplineTrajectory traj = GenerateMotion(scene, o, body_from_camera, 7, 0);
    const Stats s = Measure(scene, traj, body_from_camera, o.rest_s);
    const MotionLevelParams target = ParamsFor(level);
    std::printf(
        "%s: speed %.2f m/s (target %.2f), angular rate %.1f deg/s (target %.1f), rms jerk "
        "%.2f m/s^3, min clearance %.2f m, view distance %.2f..%.2f m\n",
        MotionLevelName(level).c_str(), s.mean_speed, target.speed_mps, s.mean_rate_dps,
        target.angular_rate_dps, s.rms_jerk, s.min_clearance, s.min_view, s.max_view);
    EXPECT_GT(s.rms_jerk, previous_jerk);  // harder levels are jerkier
    previous_jerk = s.rms_jerk;
    EXPECT_NEAR(s.mean_speed, target.speed_mps, 0.2 * target.speed_mps);
    EXPECT_NEAR(s.mean_rate_dps, target.angular_rate_dps, 0.25 * target.angular_rate_dps);
    EXPECT_GT(s.min_clearance, 0.5);
    EXPECT_GT(s.min_view, 0.7);  // always looking at a surface, never into it
    EXPECT_LT(s.max_view, 10.0);
    EXPECT_LT(s.start_speed, 1e-9);  // starts at rest
  }
}

TEST(MotionGenerator, SameSeedSameTrajectory) {
  const Scene scene = TinyScene("vicon_room");
  MotionOptions o;
  o.duration_s = 10;
  const SE3d b = EurocCam0().body_from_camera;
  const SplineTrajectory a = GenerateMotion(scene, o, b, 3, 0);
  const SplineTrajectory c = GenerateMotion(scene, o, b, 3, 0);
  const SplineTrajectory d = GenerateMotion(scene, o, b, 4, 0);
  const std::int64_t t = 7'000'000'000;
  EXPECT_EQ(a.WorldFromBody(t).translation(), c.WorldFromBody(t).translation());
  EXPECT_NE(a.WorldFromBody(t).translation(), d.WorldFromBody(t).translation());
}

}  // namespace
}  // namespace pkslam::sim
