// End-to-end: a short simulated sequence that circles the Vicon-room scene twice is rendered
// (`pkslam simulate --trajectory`), then `pkslam run` must detect and close the loop
// (stats.json) and keep every tracked frame in one map; `pkslam eval` bounds the error.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "tests/support/test_data.h"

namespace pkslam {
namespace {

using testing::RunPkslam;

// world_from_body samples (TUM) of a circle of `radius` m at 1.4 m height, the camera looking
// outwards (25 deg towards the direction of travel), `laps` laps of `lap_s` seconds.
void WriteCircleTrajectory(const std::filesystem::path& file, double radius, double lap_s,
                           double laps) {
  Eigen::Matrix4d body_from_camera;  // the simulator's cam0 (EuRoC VI-sensor) extrinsics
  body_from_camera << 0.014865542982048563, -0.999880929698284, 0.004140296794206974,
      -0.0216401454975, 0.9995572490081694, 0.014967213324960649, 0.025715529947981965,
      -0.064676986768, -0.025774436697419814, 0.0037561883579469834, 0.9996607271779513,
      0.00981073058949, 0, 0, 0, 1;
  const Eigen::Matrix4d camera_from_body = body_from_camera.inverse();
  std::ofstream out(file);
  const double duration = laps * lap_s + 1.0;
  for (int k = 0; k <= static_cast<int>(duration * 200); ++k) {
    const double t = k / 200.0;
    const double theta = 2 * M_PI * t / lap_s;
    const Eigen::Vector3d centre(radius * std::cos(theta), radius * std::sin(theta),
                                 1.4 + 0.1 * std::sin(3 * theta));
    const double yaw = theta + 25.0 * M_PI / 180.0;
    const Eigen::Vector3d forward =
        Eigen::Vector3d(std::cos(yaw), std::sin(yaw), -0.15).normalized();
    const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
    Eigen::Matrix4d world_from_camera = Eigen::Matrix4d::Identity();
    world_from_camera.block<3, 1>(0, 0) = right;
    world_from_camera.block<3, 1>(0, 1) = forward.cross(right);
    world_from_camera.block<3, 1>(0, 2) = forward;
    world_from_camera.block<3, 1>(0, 3) = centre;
    const Eigen::Matrix4d world_from_body = world_from_camera * camera_from_body;
    const Eigen::Quaterniond q(Eigen::Matrix3d(world_from_body.block<3, 3>(0, 0)));
    out << fmt::format("{:.6f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}\n", t,
                       world_from_body(0, 3), world_from_body(1, 3), world_from_body(2, 3), q.x(),
                       q.y(), q.z(), q.w());
  }
}

std::string ReadFile(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int JsonInt(const std::string& json, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(json, m, std::regex("\"" + key + "\": *(-?[0-9]+)"))) return -1;
  return std::stoi(m[1]);
}

TEST(LoopClosingEndToEnd, TwoLapsCloseTheLoopInOneMap) {
  const auto dir = testing::MakeTempDir("loop_e2e");
  WriteCircleTrajectory(dir / "circle.txt", 0.8, 7.0, 2.0);
  const auto sim = RunPkslam(fmt::format(
      "--log-level warn simulate --out '{}' --trajectory '{}' --quality fast --quiet --no-cloud "
      "--realism ideal",
      (dir / "seq").string(), (dir / "circle.txt").string()));
  ASSERT_EQ(sim.exit_code, 0) << sim.output;

  const auto run = RunPkslam(fmt::format("--log-level warn run --dataset '{}' --out '{}' --quiet",
                                         (dir / "seq").string(), (dir / "out").string()));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string stats = ReadFile(dir / "out" / "stats.json");
  EXPECT_GE(JsonInt(stats, "num_loops"), 1) << stats.substr(0, 2000);
  EXPECT_EQ(JsonInt(stats, "maps"), 1);
  const int frames = JsonInt(stats, "frames");
  const int in_trajectory = JsonInt(stats, "frames_in_trajectory");
  EXPECT_GE(in_trajectory, 0.95 * frames);

  const auto eval = RunPkslam(
      fmt::format("eval --est '{}' --gt '{}'", (dir / "out" / "trajectory_body.txt").string(),
                  (dir / "seq" / "mav0" / "state_groundtruth_estimate0" / "data.csv").string()));
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(eval.output, m, std::regex("rmse[^0-9]*([0-9.]+)"))) << eval.output;
  EXPECT_LT(std::stod(m[1]), 0.05) << eval.output;
}

}  // namespace
}  // namespace pkslam
