#include "sim/reference_cloud.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "io/trajectory.h"
#include "sim/euroc_writer.h"
#include "sim/simulator.h"
#include "tests/support/test_data.h"

namespace pkslam::sim {
namespace {

namespace fs = std::filesystem;

// Positions of a reference PLY as WriteReferenceCloud writes it (25-byte vertices).
std::vector<Eigen::Vector3f> ReadPositions(const fs::path& file) {
  const std::string bytes = testing::ReadFileBytes(file);
  const std::size_t header_end = bytes.find("end_header\n");
  EXPECT_NE(header_end, std::string::npos) << file;
  const std::size_t count_at = bytes.find("element vertex ");
  EXPECT_EQ(bytes.find("element", count_at + 1), std::string::npos) << file;
  const std::size_t count = std::stoul(bytes.substr(count_at + 15));
  const std::size_t data = header_end + 11;
  EXPECT_EQ(bytes.size() - data, count * 25) << file;
  std::vector<Eigen::Vector3f> points(count);
  for (std::size_t i = 0; i < count; ++i) {
    std::memcpy(points[i].data(), bytes.data() + data + i * 25, 12);
  }
  return points;
}

SimulationOptions ShortReplay(const fs::path& shared, const fs::path& out) {
  SimulationOptions o;
  o.output_dir = out;
  o.trajectory = shared / "euroc/groundtruth/V1_02_medium.txt";
  o.start_s = 20.0;
  o.duration_s = 0.3;
  o.quality = Quality::kFast;
  o.quiet = true;
  o.cloud_spacing_m = 0.05;
  o.visibility_cell_m = 0.1;
  o.observed_cell_m = 0.1;  // the same cells: the observed cloud is a subset of the full one
  o.observed_range_m = 2.0;
  return o;
}

TEST(ReferenceCloud, ObservedCloudIsWhatCam0SawWithinTheRange) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path out = testing::MakeTempDir("sim_observed");
  const SimulationOptions o = ShortReplay(shared, out);
  const SimulationSummary s = RunSimulation(o);
  const std::vector<Eigen::Vector3f> full = ReadPositions(out / "reference_cloud.ply");
  const std::vector<Eigen::Vector3f> observed = ReadPositions(out / "reference_observed.ply");
  EXPECT_EQ(s.observed_points, observed.size());
  EXPECT_EQ(s.cloud_points, full.size());
  ASSERT_GT(observed.size(), 200u);
  EXPECT_LT(observed.size(), full.size() / 2);
  EXPECT_NE(testing::ReadFileBytes(out / "reference_observed.ply").find("comment max_depth_m 2"),
            std::string::npos);

  // Observed points are samples of the full cloud.
  std::set<std::tuple<float, float, float>> full_set;
  for (const auto& p : full) full_set.insert({p.x(), p.y(), p.z()});
  for (const auto& p : observed) ASSERT_TRUE(full_set.count({p.x(), p.y(), p.z()})) << p;

  // The cam0 poses of the frames (ground truth x EuRoC's T_BS).
  const Trajectory gt = ReadTrajectory(out / "mav0/state_groundtruth_estimate0/data.csv");
  const CameraRig cam0 = EurocCam0();
  std::vector<SE3d> camera_from_world;
  for (const StampedPose& p : gt.poses) {
    if ((p.t_ns - gt.poses.front().t_ns) % 50'000'000 == 0) {
      camera_from_world.push_back((p.pose * cam0.body_from_camera).Inverse());
    }
  }
  ASSERT_EQ(camera_from_world.size(), 7u);  // 20 Hz over 0.3 s
  // A cell counts as seen when a ray hit any part of it: its samples may lie up to a cell
  // diagonal beyond the range and outside the image.
  const double slack = 0.1 * std::sqrt(2.0);
  // Smallest depth at which a frame has the point inside its image (widened by the slack).
  auto min_depth = [&](const Eigen::Vector3f& p) {
    double best = 1e9;
    for (const SE3d& c : camera_from_world) {
      const Eigen::Vector3d q = c * p.cast<double>();
      if (q.z() <= 0.05) continue;
      const auto uv = cam0.camera.Project(q);
      const double margin = cam0.camera.fx() * slack / q.z() + 1.0;
      if (!uv || uv->x() < -margin || uv->y() < -margin ||
          uv->x() >= cam0.camera.width() + margin || uv->y() >= cam0.camera.height() + margin) {
        continue;
      }
      best = std::min(best, q.z());
    }
    return best;
  };
  for (const auto& p : observed) ASSERT_LE(min_depth(p), o.observed_range_m + slack) << p;
  // Surfaces seen only from farther away are in the full cloud alone.
  int far_only = 0;
  for (const auto& p : full) far_only += min_depth(p) > o.observed_range_m + slack;
  EXPECT_GT(far_only, static_cast<int>(full.size() / 2));

  // --reference-only writes the same two clouds and nothing else.
  const fs::path ref_only = testing::MakeTempDir("sim_reference_only");
  SimulationOptions r = o;
  r.output_dir = ref_only;
  r.reference_only = true;
  const SimulationSummary rs = RunSimulation(r);
  EXPECT_EQ(rs.layout, "reference");
  EXPECT_EQ(testing::ReadFileBytes(ref_only / "reference_cloud.ply"),
            testing::ReadFileBytes(out / "reference_cloud.ply"));
  EXPECT_EQ(testing::ReadFileBytes(ref_only / "reference_observed.ply"),
            testing::ReadFileBytes(out / "reference_observed.ply"));
  EXPECT_FALSE(fs::exists(ref_only / "mav0"));
  EXPECT_FALSE(fs::exists(ref_only / "sim.yaml"));

  // observed_range_m = 0: no observed cloud.
  const fs::path none = testing::MakeTempDir("sim_no_observed");
  SimulationOptions n = o;
  n.output_dir = none;
  n.observed_range_m = 0.0;
  n.reference_only = true;
  EXPECT_EQ(RunSimulation(n).observed_points, 0u);
  EXPECT_TRUE(fs::exists(none / "reference_cloud.ply"));
  EXPECT_FALSE(fs::exists(none / "reference_observed.ply"));
}

}  // namespace
}  // namespace pkslam::sim
