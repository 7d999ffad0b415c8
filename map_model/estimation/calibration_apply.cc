#include "map_model/estimation/calibration_apply.h"

#include "core/util/error.h"
#include "estimators/optim/point_refinement.h"
#include "imu/preintegration.h"
#include "map_model/estimation/bundle_collect.h"
#include "map_model/estimation/global_bundle_merge.h"
#include "map_model/estimation/inertial_bundle_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"

namespace pkslam {
namespace {

// Per axis, (1 + k_from) / (1 + k_to): what moves a gyro sample corrected for scale error
// k_from to one corrected for k_to.
Eigen::Vector3d GyroRescale(const RigCalibration& from, const RigCalibration& to) {
  return (Eigen::Vector3d::Ones() + from.gyro_scale)
      .cwiseQuotient(Eigen::Vector3d::Ones() + to.gyro_scale);
}

// (I + E_to)^-1 (I + E_from): what moves an accelerometer sample corrected for axis errors
// E_from to one corrected for E_to.
Eigen::Matrix3d AccelTransform(const RigCalibration& from, const RigCalibration& to) {
  if (from.accel_axes == to.accel_axes) return Eigen::Matrix3d::Identity();
  return (Eigen::Matrix3d::Identity() + to.accel_axes).inverse() *
         (Eigen::Matrix3d::Identity() + from.accel_axes);
}

// A keyframe's preintegration and biases moved to new axis error corrections.
void MoveKeyFrameImu(const MapWriteLock& lock, const Eigen::Vector3d& gyro_factor,
                     const Eigen::Matrix3d& accel_transform, KeyFrame* kf) {
  KeyFrameImu& imu = kf->mutable_imu(lock);
  if (gyro_factor != Eigen::Vector3d::Ones()) {
    if (imu.from_previous) RescaleGyro(gyro_factor, &*imu.from_previous);
    imu.state.bias.gyro = imu.state.bias.gyro.cwiseProduct(gyro_factor);
  }
  if (accel_transform != Eigen::Matrix3d::Identity()) {
    if (imu.from_previous) TransformAccel(accel_transform, &*imu.from_previous);
    imu.state.bias.accel = accel_transform * imu.state.bias.accel;
  }
}

}  // namespace

void MoveToCalibration(const MapWriteLock& lock, Atlas* atlas, const RigCalibration& calibration,
                       const RigSetup& setup) {
  RequireWriteLock(lock, "MoveToCalibration");
  const RigSetup old = atlas->rig_setup();
  const Eigen::Vector3d gyro_factor = GyroRescale(atlas->calibration(), calibration);
  const Eigen::Matrix3d accel_transform = AccelTransform(atlas->calibration(), calibration);
  if (gyro_factor != Eigen::Vector3d::Ones() || accel_transform != Eigen::Matrix3d::Identity()) {
    // The chain's preintegrations were integrated with the old corrections (tracking corrects
    // each sample as it integrates it: Tracker::SetImuAxisErrors).
    for (Map* map : atlas->maps()) {
      for (const auto& [id, kf] : map->keyframes()) {
        MoveKeyFrameImu(lock, gyro_factor, accel_transform, kf.get());
      }
      for (const auto& [id, kf] : map->retired_keyframes()) {
        MoveKeyFrameImu(lock, gyro_factor, accel_transform, kf.get());
      }
    }
  }
  if (old.rig != nullptr) {
    // The body keeps its place: the tracking camera moves by new_from_old.
    const SE3d new_from_old = setup.rig->body_from_camera.Inverse() * old.rig->body_from_camera;
    const RigWarp warp(old, setup);
    for (Map* map : atlas->maps()) {
      for (const auto& [id, kf] : map->keyframes())
        kf->Recalibrate(lock, setup.rig, warp, new_from_old);
      for (const auto& [id, kf] : map->retired_keyframes()) {
        kf->Recalibrate(lock, setup.rig, warp, new_from_old);
      }
    }
  }
  atlas->SetCalibration(lock, calibration, setup);
}

int RefinePointsToCalibration(Atlas* atlas, MapId map_id) {
  BundleProblem problem;
  std::vector<Eigen::Vector3d> refined;
  {
    auto lock = MapReader(*atlas).Lock();
    const Map* map = atlas->FindMap(map_id);
    if (map == nullptr) return 0;
    problem = CollectGlobalBundle(lock, *map);
    refined = RefinePoints(problem);
  }
  auto lock = MapEditor(atlas).Write(MapEdit::kCalibration);
  Map* map = atlas->FindMap(map_id);
  if (map == nullptr) return 0;
  int moved = 0;
  for (std::size_t i = 0; i < problem.points.size(); ++i) {
    if (refined[i] == problem.points[i].position_world) continue;
    const MapPointPtr point = map->MapPointById(problem.points[i].point_id);
    // A point changed meanwhile (local BA, fusion) keeps its newer position.
    if (point == nullptr || point->IsBad() ||
        point->position() != problem.points[i].position_world) {
      continue;
    }
    point->SetPosition(lock, refined[i]);
    point->UpdateNormalAndDepth(lock);
    ++moved;
  }
  return moved;
}

void ApplyCalibration(const MapWriteLock& lock, Atlas* atlas, Map* map,
                      const CalibrationBundleProblem& problem,
                      const CalibrationBundleResult& result, const RigSetup& setup) {
  // The adjustment's gyro biases are those of rates corrected with the problem's scale.
  const Eigen::Vector3d gyro_factor = GyroRescale(problem.initial, result.estimate);
  MoveToCalibration(lock, atlas, result.estimate, setup);
  if (map == nullptr) return;
  const InertialBundleProblem& bundle = problem.bundle;
  PKSLAM_CHECK(result.world_from_body.size() == bundle.visual.keyframes.size(),
               "calibration result ({} keyframes) does not match the problem ({})",
               result.world_from_body.size(), bundle.visual.keyframes.size());
  InertialBundleResult written;
  written.visual = result.bundle.visual;
  written.visual.outlier_observations.clear();
  written.visual.camera_from_world.clear();
  const SE3d body_from_camera = setup.rig->body_from_camera;
  for (const SE3d& world_from_body : result.world_from_body) {
    written.visual.camera_from_world.push_back((world_from_body * body_from_camera).Inverse());
  }
  written.velocities = result.bundle.velocities;
  written.biases = result.bundle.biases;
  for (ImuBias& b : written.biases) b.gyro = b.gyro.cwiseProduct(gyro_factor);
  MergeGlobalBundle(
      lock, map, bundle.visual,
      [&] {
        if (problem.inertial) {
          ApplyInertialBundle(lock, map, bundle, written);
        } else {
          ApplyBundle(lock, map, bundle.visual, written.visual);
        }
      },
      /*apply_sets_velocities=*/problem.inertial);
  map->RecordWorldChange(lock, {});
}

}  // namespace pkslam
