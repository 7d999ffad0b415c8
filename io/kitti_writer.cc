#include "io/kitti_writer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "core/util/output_file.h"
#include "io/euroc_dataset.h"
#include "io/kitti_dataset.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

// The rig's baseline (m) when cam1 is cam0 moved along its x axis with the same intrinsics and
// no distortion: a rectified pair, as KITTI's images are.
double RectifiedBaseline(const EurocDataset& d) {
  const EurocCameraSensor& c0 = d.cam0_sensor();
  const EurocCameraSensor& c1 = d.cam1_sensor();
  const fs::path yaml = d.mav0() / "cam1" / "sensor.yaml";
  auto has_distortion = [](const EurocCameraSensor& c) {
    return std::any_of(c.distortion_coefficients.begin(), c.distortion_coefficients.end(),
                       [](double v) { return v != 0.0; });
  };
  if (c0.intrinsics != c1.intrinsics || c0.width != c1.width || c0.height != c1.height ||
      has_distortion(c0) || has_distortion(c1)) {
    throw InputError(yaml,
                     "KITTI's layout needs a rectified pair: cam0 and cam1 with the same "
                     "intrinsics and no distortion");
  }
  const SE3d cam0_from_cam1 = c0.body_from_camera.Inverse() * c1.body_from_camera;
  const Eigen::Vector3d t = cam0_from_cam1.translation();
  if (cam0_from_cam1.so3().Angle() > 1e-9 || std::abs(t.y()) > 1e-9 || std::abs(t.z()) > 1e-9 ||
      !(t.x() > 0)) {
    throw InputError(yaml,
                     "KITTI's layout needs cam1 to the right of cam0 along its x axis, "
                     "with the same orientation");
  }
  return t.x();
}

void LinkOrCopy(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::remove(to, ec);
  fs::create_hard_link(from, to, ec);
  if (ec) fs::copy_file(from, to, fs::copy_options::overwrite_existing);
}

// The ground-truth sample nearest `t_ns` (within 2.5 ms).
const EurocGroundTruthState& GroundTruthAt(const EurocDataset& d, std::int64_t t_ns) {
  const auto& gt = d.ground_truth();
  auto it =
      std::lower_bound(gt.begin(), gt.end(), t_ns,
                       [](const EurocGroundTruthState& s, std::int64_t t) { return s.t_ns < t; });
  if (it == gt.end() || (it != gt.begin() && t_ns - std::prev(it)->t_ns < it->t_ns - t_ns)) {
    it = std::prev(it);
  }
  if (std::llabs(it->t_ns - t_ns) > 2'500'000) {
    throw InputError(d.mav0() / "state_groundtruth_estimate0/data.csv",
                     fmt::format("no sample within 2.5 ms of the frame at {} ns", t_ns));
  }
  return *it;
}

std::string ProjectionRow(const char* name, double fx, double fy, double cx, double cy, double tx) {
  return fmt::format("{}: {:.12e} 0 {:.12e} {:.12e} 0 {:.12e} {:.12e} 0 0 0 1 0\n", name, fx, cx,
                     tx, fy, cy);
}

}  // namespace

void WriteKittiLayoutFromEuroc(const fs::path& euroc_root, const fs::path& kitti_root,
                               const std::string& name) {
  const EurocDataset d = EurocDataset::Open(euroc_root);
  if (!d.has_cam1()) throw InputError(d.mav0() / "cam1", "KITTI's layout needs cam1");
  if (!d.has_ground_truth()) {
    throw InputError(d.mav0() / "state_groundtruth_estimate0", "KITTI's layout needs poses");
  }
  const double baseline = RectifiedBaseline(d);
  const auto& k = d.cam0_sensor().intrinsics;
  const fs::path seq = kitti_root / "sequences" / name;
  fs::create_directories(seq / "image_0");
  fs::create_directories(seq / "image_1");
  fs::create_directories(kitti_root / "poses");

  OutputFile times(seq / "times.txt");
  Trajectory poses;
  const std::int64_t t0 = d.stereo_pairs().front().t_ns;
  const SE3d body_from_cam0 = d.cam0_sensor().body_from_camera;
  std::optional<SE3d> first_cam0_from_world;
  for (std::size_t i = 0; i < d.stereo_pairs().size(); ++i) {
    const StereoPair& p = d.stereo_pairs()[i];
    LinkOrCopy(d.cam0().images[p.left].path, seq / "image_0" / fmt::format("{:06d}.png", i));
    LinkOrCopy(d.cam1().images[p.right].path, seq / "image_1" / fmt::format("{:06d}.png", i));
    times.stream() << fmt::format("{:.6e}\n", static_cast<double>(p.t_ns - t0) * 1e-9);
    const SE3d world_from_cam0 = GroundTruthAt(d, p.t_ns).world_from_body * body_from_cam0;
    if (!first_cam0_from_world) first_cam0_from_world = world_from_cam0.Inverse();
    poses.poses.push_back({p.t_ns - t0, *first_cam0_from_world * world_from_cam0});
  }
  times.Commit();
  WriteKittiPoses(poses, kitti_root / "poses" / (name + ".txt"));
  OutputFile calib(seq / "calib.txt");
  calib.stream() << ProjectionRow("P0", k[0], k[1], k[2], k[3], 0.0)
                 << ProjectionRow("P1", k[0], k[1], k[2], k[3], -k[0] * baseline)
                 << ProjectionRow("P2", k[0], k[1], k[2], k[3], 0.0)
                 << ProjectionRow("P3", k[0], k[1], k[2], k[3], -k[0] * baseline)
                 << "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n";
  calib.Commit();
}

}  // namespace pkslam
