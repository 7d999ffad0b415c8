// The Atlas as plain values, for map files (map_model/storage/map_file.h): every keyframe,
// map point and map with its links written as ids instead of pointers. AtlasStorage
// (atlas_storage.h) turns a live Atlas into these records and back; map_file.cc writes them.
//
// Kept: live keyframes and points (culled ones are gone from the map and are not written),
// features, descriptors, BoW and feature vectors, poses, point-keyframe observations, the
// covisibility graph with its weights, the spanning tree, loop edges, the inertial chain with
// its preintegrations, states and marginalisation priors, each map's IMU status and world-change
// log, the id counters, the camera the map was built with and its calibration.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/bow/bow_vector.h"
#include "core/features/descriptor.h"
#include "core/geometry/se3.h"
#include "core/imu/imu_types.h"
#include "core/imu/inertial_state.h"
#include "core/util/ids.h"

namespace pkslam {

struct KeyPointRecord {
  float x = 0, y = 0, size = 0, angle = 0, response = 0;
  std::int32_t octave = 0;
};

struct KeyFrameRecord {
  KeyFrameId id = kInvalidId;
  FrameId frame_id = kInvalidId;
  std::int64_t t_ns = 0;
  std::vector<KeyPointRecord> keypoints;
  std::vector<KeyPointRecord> keypoints_undistorted;
  std::vector<float> right_u;
  std::vector<float> depth;
  std::vector<float> depth_sigma;
  std::vector<Descriptor> descriptors;
  std::vector<BowEntry> bow;
  std::vector<std::pair<NodeId, std::uint32_t>> feature_vector;  // (node, feature index)
  SE3d camera_from_world;
  std::vector<MapPointId> map_points;  // per keypoint; kInvalidId: none
  std::vector<std::pair<KeyFrameId, std::int32_t>> connections;  // covisibility: (id, weight)
  KeyFrameId parent = kInvalidId;
  std::vector<KeyFrameId> loop_edges;
  bool not_erase = false;
  SE3d camera_from_parent;
  // Inertial chain (KeyFrameImu).
  std::optional<PreintegratedImu> imu_from_previous;
  KeyFrameId imu_previous = kInvalidId;
  KeyFrameId imu_next = kInvalidId;
  InertialState imu_state;
  std::optional<InertialStatePrior> imu_prior;
};

struct MapPointRecord {
  MapPointId id = kInvalidId;
  KeyFrameId first_keyframe = kInvalidId;
  KeyFrameId reference_keyframe = kInvalidId;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Descriptor descriptor;
  double min_distance = 0;  // the stored (unscaled) bounds
  double max_distance = 0;
  std::vector<std::pair<KeyFrameId, std::int32_t>> observations;  // (keyframe, keypoint index)
  std::int32_t visible = 1;
  std::int32_t found = 1;
};

struct WorldChangeRecord {
  std::int32_t kind = 0;  // WorldChange::Kind
  SO3d rotation;
  double scale = 1.0;
};

struct MapRecord {
  MapId id = -1;
  KeyFrameId origin = kInvalidId;
  KeyFrameId max_keyframe_id = kInvalidId;
  std::int32_t change_index = 0;
  bool imu_initialized = false;
  bool inertial_ba1_done = false;
  bool inertial_ba2_done = false;
  double gravity_refinement_observability = 0;
  std::int64_t imu_init_t_ns = 0;
  std::vector<WorldChangeRecord> world_changes;
  double applied_scale = 1.0;
  std::int32_t world_transforms = 0;
  std::vector<KeyFrameRecord> keyframes;  // id order
  std::vector<MapPointRecord> points;     // id order
};

// The camera the map was built with: loading compares it with the run's (a map is only valid
// for the camera whose pixels its features are in).
struct CameraRecord {
  std::int32_t sensor = 0;  // Sensor
  std::string model;        // CameraModel::ToString()
  double fx = 0, fy = 0, cx = 0, cy = 0, bf = 0;
  SE3d body_from_camera;
};

// The calibration the map's keypoints are in (online calibration: an estimate, not the file's;
// map file version 2). Cameras as CameraModel::Pinhole arguments.
struct CalibrationRecord {
  struct Camera {
    std::int32_t width = 0, height = 0;
    double fx = 0, fy = 0, cx = 0, cy = 0;
    std::vector<double> distortion;
  };
  std::vector<Camera> cameras;
  SE3d body_from_cam0;
  SE3d cam1_from_cam0;
  double time_offset_s = 0;
  // RigCalibration::gyro_scale (version 3; zero in older files).
  std::array<double, 3> gyro_scale{};
  // RigCalibration::accel_axes, row-major (version 4; zero in older files).
  std::array<double, 9> accel_axes{};
  // Keyframes tracked with a non-zero time offset (KeyFrameImu::time_offset_s).
  std::vector<std::pair<KeyFrameId, double>> keyframe_time_offsets;
};

struct AtlasRecord {
  std::uint64_t vocabulary_fingerprint = 0;
  CameraRecord camera;
  // Version 2 files; absent in version 1 files (the rig's calibration was the settings').
  std::optional<CalibrationRecord> calibration;
  MapId current_map = -1;
  MapId next_map_id = 0;
  FrameId next_frame_id = 0;
  KeyFrameId next_keyframe_id = 0;
  MapPointId next_point_id = 0;
  std::vector<MapRecord> maps;
};

}  // namespace pkslam
