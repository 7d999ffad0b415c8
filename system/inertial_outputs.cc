#include "system/inertial_outputs.h"

#include <fmt/format.h>

#include <fstream>
#include <mutex>
#include <shared_mutex>

#include "core/util/error.h"
#include "core/util/output_file.h"
#include "io/trajectory.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"

namespace pkslam {

void WriteInertialOutputs(const SlamSystem& system, const std::filesystem::path& out_dir) {
  if (!IsInertial(system.rig().sensor)) return;
  Trajectory online;
  const SE3d camera_from_body = system.rig().body_from_camera.Inverse();
  for (const FrameRecord& r : system.tracker().records()) {
    if (r.camera_from_world_online) {
      online.poses.push_back({r.t_ns, r.camera_from_world_online->Inverse() * camera_from_body});
    }
  }
  WriteTrajectory(online, out_dir / "trajectory_online_body.txt", TrajectoryFormat::kTum);
  // The keyframe chain right after each IMU initialisation stage.
  const LocalMappingStats mapping = system.mapping_stats();
  for (std::size_t i = 0; i < mapping.imu_stages.size(); ++i) {
    const ImuStageSnapshot& stage = mapping.imu_stages[i];
    Trajectory chain;
    for (const auto& [t_ns, pose] : stage.world_from_body) chain.poses.push_back({t_ns, pose});
    WriteTrajectory(chain,
                    out_dir / fmt::format("imu_stage{}_{}_keyframes_body.txt", i, stage.stage),
                    TrajectoryFormat::kTum);
  }
  const std::filesystem::path file = out_dir / "keyframes_imu.csv";
  OutputFile output(file);
  std::ostream& out = output.stream();
  out << "time,vx,vy,vz,bgx,bgy,bgz,bax,bay,baz,valid,map_imu_initialized\n";
  const Atlas& atlas = system.atlas();
  auto lock = MapReader(atlas).Lock();
  const Map* best = nullptr;
  for (const Map* m : atlas.maps()) {
    if (best == nullptr || m->NumKeyFrames() > best->NumKeyFrames()) best = m;
  }
  if (best != nullptr) {
    for (const auto& [id, kf] : best->keyframes()) {
      const InertialState& s = kf->imu().state;
      out << fmt::format(
          "{:.9f},{:.6f},{:.6f},{:.6f},{:.7f},{:.7f},{:.7f},{:.6f},{:.6f},{:.6f},{},{}\n",
          kf->t_s(), s.velocity_world.x(), s.velocity_world.y(), s.velocity_world.z(),
          s.bias.gyro.x(), s.bias.gyro.y(), s.bias.gyro.z(), s.bias.accel.x(), s.bias.accel.y(),
          s.bias.accel.z(), s.valid ? 1 : 0, best->imu_status().imu_initialized ? 1 : 0);
    }
  }
  lock.unlock();
  output.Commit();
}

}  // namespace pkslam
