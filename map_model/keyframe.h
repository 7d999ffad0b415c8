// A keyframe: the features and pose of a selected frame, its map-point associations, and its
// place in the covisibility graph and spanning tree.
//
// Threading (docs/architecture.md): all mutable state is guarded by the Atlas mutex (shared
// lock to read, exclusive to write). Every change takes the write lock (MapWriteLock) as a
// parameter and throws without it, except set_map (a map being cleared or merged moves its
// objects under its caller's lock). The feature data copied from the frame is immutable until
// the keyframe is retired.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <opencv2/core/types.hpp>
#include <optional>
#include <set>
#include <vector>

#include "core/bow/bow_vector.h"
#include "core/features/descriptor.h"
#include "core/geometry/se3.h"
#include "core/sensor/camera_rig.h"
#include "core/sensor/rig_calibration.h"
#include "map_model/feature_grid.h"
#include "map_model/keyframe_inertial.h"
#include "map_model/map_ids.h"

namespace pkslam {

class MapWriteLock;

class KeyFrame {
 public:
  // Copies the frame's features and pose; map-point slots start as in the frame.
  KeyFrame(KeyFrameId id, const Frame& frame, Map* map);
  KeyFrame(const KeyFrame&) = delete;
  KeyFrame& operator=(const KeyFrame&) = delete;

  KeyFrameId id() const { return id_; }
  FrameId frame_id() const { return frame_id_; }
  std::int64_t t_ns() const { return t_ns_; }
  double t_s() const { return static_cast<double>(t_ns_) * 1e-9; }
  const CameraRig& rig() const { return *rig_; }
  const std::shared_ptr<const CameraRig>& rig_ptr() const { return rig_; }
  Map* map() const { return map_; }
  void set_map(Map* map) { map_ = map; }

  // --- features (immutable while live) ---
  int size() const { return static_cast<int>(keypoints_un_.size()); }
  const std::vector<cv::KeyPoint>& keypoints() const { return keypoints_; }
  const std::vector<cv::KeyPoint>& keypoints_undistorted() const { return keypoints_un_; }
  const std::vector<float>& right_u() const { return right_u_; }
  const std::vector<float>& depth() const { return depth_; }
  const std::vector<Descriptor>& descriptors() const { return descriptors_; }
  const BowVector& bow() const { return bow_; }
  const FeatureVector& feature_vector() const { return feature_vector_; }
  std::vector<int> FeaturesInArea(double x, double y, double radius, int min_level = -1,
                                  int max_level = -1) const {
    return grid_.FeaturesInArea(keypoints_un_, x, y, radius, min_level, max_level);
  }
  // Into a caller-owned buffer (no allocation per query in matching loops).
  void FeaturesInArea(double x, double y, double radius, int min_level, int max_level,
                      std::vector<int>* out) const {
    grid_.FeaturesInArea(keypoints_un_, x, y, radius, min_level, max_level, out);
  }
  bool HasDepth(int i) const { return !depth_.empty() && depth_[i] > 0; }
  // As Frame::DisparityInformation (RGB-D depth information; 0 for stereo / no depth).
  double DisparityInformation(int i) const;
  std::optional<Eigen::Vector3d> UnprojectStereo(int i) const;

  // --- pose ---
  const SE3d& camera_from_world() const { return camera_from_world_; }
  const SE3d& world_from_camera() const { return world_from_camera_; }
  Eigen::Vector3d CameraCenter() const { return world_from_camera_.translation(); }
  // The IMU (body) pose: world_from_camera * camera_from_body.
  SE3d world_from_body() const { return world_from_camera_ * rig_->body_from_camera.Inverse(); }
  // Moves the keyframe (adjustments, loop correction, a rescaled or reloaded map); throws without
  // the write lock.
  void SetPose(const MapWriteLock& lock, const SE3d& camera_from_world);
  // Median depth of the observed map points (q = 0.5), or the q-quantile.
  double SceneDepthQuantile(double q = 0.5) const;

  // --- map points (one slot per keypoint) ---
  const std::vector<MapPointPtr>& map_points() const { return map_points_; }
  const MapPointPtr& map_point(int index) const { return map_points_[index]; }
  void AddMapPoint(const MapWriteLock& lock, const MapPointPtr& point, int index);
  void EraseMapPointMatch(const MapWriteLock& lock, int index);
  void EraseMapPointMatch(const MapWriteLock& lock, const MapPoint* point);
  void ReplaceMapPointMatch(const MapWriteLock& lock, int index, const MapPointPtr& point);
  // Points in slots that are non-null and not bad.
  std::vector<MapPointPtr> GoodMapPoints() const;
  // Number of good points with at least min_observations observations.
  int TrackedMapPoints(int min_observations) const;

  // --- covisibility graph ---
  // Recounts shared points with every other keyframe, keeps edges with weight >= 15 (or the
  // best one), and on the first call links this keyframe into the spanning tree.
  void UpdateConnections(const MapWriteLock& lock);
  void AddConnection(const MapWriteLock& lock, KeyFrame* kf, int weight);
  void EraseConnection(const MapWriteLock& lock, KeyFrame* kf);
  int Weight(const KeyFrame* kf) const;
  // Covisible keyframes by decreasing weight (ties: increasing id).
  const std::vector<KeyFrame*>& CovisiblesByWeight() const { return ordered_connected_; }
  std::vector<KeyFrame*> BestCovisibles(int n) const;
  std::vector<KeyFrame*> CovisiblesWithWeightAtLeast(int weight) const;
  std::vector<KeyFrame*> ConnectedKeyFrames() const;  // id order

  // --- spanning tree and loop edges ---
  KeyFrame* parent() const { return parent_; }
  void ChangeParent(const MapWriteLock& lock, KeyFrame* parent);
  const std::map<KeyFrameId, KeyFrame*>& children() const { return children_; }
  void AddChild(const MapWriteLock& lock, KeyFrame* kf);
  void EraseChild(const MapWriteLock& lock, KeyFrame* kf);
  void AddLoopEdge(const MapWriteLock& lock, KeyFrame* kf);
  const std::map<KeyFrameId, KeyFrame*>& loop_edges() const { return loop_edges_; }

  // --- life cycle ---
  // Loop closing protects keyframes it is working on; a retire request is then deferred.
  void SetNotErase(const MapWriteLock& lock);
  // Lifts the protection; retires the keyframe if a retire request was deferred (returns true).
  // Throws without the write lock.
  bool SetErase(const MapWriteLock& lock);
  // Retires the keyframe (see docs/architecture.md): leaves the graph and the live set, keeps
  // its pose relative to its parent. The map's first keyframe is never retired. Throws without
  // the write lock.
  void SetBad(const MapWriteLock& lock);
  bool IsBad() const { return bad_; }
  // For a retired keyframe: camera_from_parent at retirement.
  const SE3d& camera_from_parent() const { return camera_from_parent_; }

  // --- online calibration (map_model/estimation/calibration_apply.h) ---
  // Moves the keyframe to a new calibration of its rig: `rig` becomes its rig; a live keyframe's
  // keypoints move through `warp` (stereo: re-rectified; monocular: re-undistorted from the raw
  // keypoint) and its stereo depths are recomputed with the new bf; its pose and, if retired,
  // its pose relative to its parent are expressed in the new tracking camera,
  // new_from_old = (new camera_from_body) * (old camera_from_body)^-1, so the body keeps its
  // place. A keypoint the warp cannot map keeps its coordinates and loses its stereo match.
  // Throws without the write lock.
  void Recalibrate(const MapWriteLock& lock, std::shared_ptr<const CameraRig> rig,
                   const RigWarp& warp, const SE3d& new_from_old);

  // --- inertial sensors (map_model/keyframe_inertial.h) ---
  // Read under the Atlas lock (shared).
  const KeyFrameImu& imu() const { return imu_; }
  // The one door to change the keyframe's inertial state, prior, preintegration and time
  // offset: the Atlas's write lock is a parameter (refused at run time if not held). The chain
  // links change only through the map's InertialChain.
  KeyFrameImu& mutable_imu(const MapWriteLock& lock);

 private:
  // SetPose's work (the constructor and Recalibrate, under the lock it checked, use it too).
  void Place(const SE3d& camera_from_world);
  friend class AtlasStorage;   // map files: map_model/storage/atlas_storage.h
  friend class InertialChain;  // the temporal links (map_model/inertial_chain.h)
  // An empty keyframe that AtlasStorage fills from a map file.
  KeyFrame(KeyFrameId id, FrameId frame_id, std::int64_t t_ns, std::shared_ptr<const CameraRig> rig,
           Map* map);
  void UpdateBestCovisibles();
  void ReleaseFeatures();

  KeyFrameId id_;
  FrameId frame_id_;
  std::int64_t t_ns_;
  std::shared_ptr<const CameraRig> rig_;
  Map* map_;

  std::vector<cv::KeyPoint> keypoints_;
  std::vector<cv::KeyPoint> keypoints_un_;
  std::vector<float> right_u_;
  std::vector<float> depth_;
  std::vector<float> depth_sigma_;
  std::vector<Descriptor> descriptors_;
  FeatureGrid grid_;
  BowVector bow_;
  FeatureVector feature_vector_;

  SE3d camera_from_world_;
  SE3d world_from_camera_;

  std::vector<MapPointPtr> map_points_;

  std::map<KeyFrameId, std::pair<KeyFrame*, int>> connections_;  // id -> (keyframe, weight)
  std::vector<KeyFrame*> ordered_connected_;
  std::vector<int> ordered_weights_;
  bool first_connection_ = true;

  KeyFrame* parent_ = nullptr;
  std::map<KeyFrameId, KeyFrame*> children_;
  std::map<KeyFrameId, KeyFrame*> loop_edges_;

  bool bad_ = false;
  bool not_erase_ = false;
  bool to_be_erased_ = false;
  SE3d camera_from_parent_;
  KeyFrameImu imu_;  // guarded by the Atlas mutex
};

}  // namespace pkslam
