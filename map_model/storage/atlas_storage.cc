#include "map_model/storage/atlas_storage.h"

#include <algorithm>
#include <map>
#include <opencv2/core/types.hpp>
#include <utility>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/keyframe_database.h"
#include "map_model/map.h"
#include "map_model/map_point.h"
#include "map_model/world_change.h"

namespace pkslam {
namespace {

std::vector<KeyPointRecord> ToRecords(const std::vector<cv::KeyPoint>& keypoints) {
  std::vector<KeyPointRecord> out;
  out.reserve(keypoints.size());
  for (const cv::KeyPoint& k : keypoints) {
    out.push_back({k.pt.x, k.pt.y, k.size, k.angle, k.response, k.octave});
  }
  return out;
}

std::vector<cv::KeyPoint> FromRecords(const std::vector<KeyPointRecord>& records) {
  std::vector<cv::KeyPoint> out;
  out.reserve(records.size());
  for (const KeyPointRecord& r : records) {
    out.emplace_back(cv::Point2f(r.x, r.y), r.size, r.angle, r.response, r.octave);
  }
  return out;
}

// Links to objects outside the saved set (culled, or in another map) are not written.
template <typename Ptr>
bool Saved(const Ptr& object, const Map* map) {
  return object != nullptr && !object->IsBad() && object->map() == map;
}

}  // namespace

AtlasRecord AtlasStorage::Snapshot(const Atlas& atlas, const CameraRig& rig,
                                   std::uint64_t vocabulary_fingerprint) {
  AtlasRecord out;
  out.vocabulary_fingerprint = vocabulary_fingerprint;
  out.camera.sensor = static_cast<std::int32_t>(rig.sensor);
  out.camera.model = rig.camera.ToString();
  out.camera.fx = rig.fx;
  out.camera.fy = rig.fy;
  out.camera.cx = rig.cx;
  out.camera.cy = rig.cy;
  out.camera.bf = rig.bf;
  out.camera.body_from_camera = rig.body_from_camera;
  if (!atlas.calibration().cameras.empty()) {
    out.calibration = ToCalibrationRecord(atlas.calibration());
  }
  out.current_map = atlas.current_ != nullptr ? atlas.current_->id() : -1;
  out.next_map_id = atlas.next_map_id_;
  out.next_frame_id = atlas.next_frame_id_.load();
  out.next_keyframe_id = atlas.next_kf_id_.load();
  out.next_point_id = atlas.next_point_id_.load();
  for (const auto& map : atlas.maps_) {
    if (map->keyframes_.empty()) continue;
    MapRecord& m = out.maps.emplace_back();
    m.id = map->id_;
    m.origin = Saved(map->origin_, map.get()) ? map->origin_->id() : kInvalidId;
    m.max_keyframe_id = map->max_kf_id_;
    m.change_index = map->change_index_;
    m.imu_initialized = map->imu_status_.imu_initialized;
    m.inertial_ba1_done = map->imu_status_.inertial_ba1_done;
    m.inertial_ba2_done = map->imu_status_.inertial_ba2_done;
    m.gravity_refinement_observability = map->imu_status_.gravity_refinement_observability;
    m.imu_init_t_ns = map->imu_status_.imu_init_t_ns;
    for (const WorldChange& c : map->world_changes_) {
      m.world_changes.push_back({static_cast<std::int32_t>(c.kind), c.rotation, c.scale});
    }
    m.applied_scale = map->applied_scale_;
    m.world_transforms = map->world_transforms_;
    for (const auto& [id, kf] : map->keyframes_) {
      KeyFrameRecord& k = m.keyframes.emplace_back();
      k.id = kf->id_;
      k.frame_id = kf->frame_id_;
      k.t_ns = kf->t_ns_;
      k.keypoints = ToRecords(kf->keypoints_);
      k.keypoints_undistorted = ToRecords(kf->keypoints_un_);
      k.right_u = kf->right_u_;
      k.depth = kf->depth_;
      k.depth_sigma = kf->depth_sigma_;
      k.descriptors = kf->descriptors_;
      k.bow = kf->bow_.entries();
      for (const FeatureGroup& g : kf->feature_vector_) {
        for (std::uint32_t f : g.features) k.feature_vector.emplace_back(g.node_id, f);
      }
      k.camera_from_world = kf->camera_from_world_;
      k.map_points.reserve(kf->map_points_.size());
      for (const MapPointPtr& p : kf->map_points_) {
        k.map_points.push_back(Saved(p, map.get()) && map->map_points_.count(p->id()) > 0
                                   ? p->id()
                                   : kInvalidId);
      }
      for (const auto& [other_id, entry] : kf->connections_) {
        if (Saved(entry.first, map.get())) k.connections.emplace_back(other_id, entry.second);
      }
      k.parent = Saved(kf->parent_, map.get()) ? kf->parent_->id() : kInvalidId;
      for (const auto& [other_id, other] : kf->loop_edges_) {
        if (Saved(other, map.get())) k.loop_edges.push_back(other_id);
      }
      k.not_erase = kf->not_erase_;
      k.camera_from_parent = kf->camera_from_parent_;
      k.imu_from_previous = kf->imu().from_previous;
      k.imu_previous =
          Saved(kf->imu().previous(), map.get()) ? kf->imu().previous()->id() : kInvalidId;
      k.imu_next = Saved(kf->imu().next(), map.get()) ? kf->imu().next()->id() : kInvalidId;
      k.imu_state = kf->imu().state;
      k.imu_prior = kf->imu().prior;
      if (kf->imu().time_offset_s != 0.0 && out.calibration) {
        out.calibration->keyframe_time_offsets.emplace_back(kf->id(), kf->imu().time_offset_s);
      }
    }
    for (const auto& [id, point] : map->map_points_) {
      if (point->IsBad()) continue;
      MapPointRecord& p = m.points.emplace_back();
      p.id = point->id_;
      p.first_keyframe = point->first_kf_id_;
      p.reference_keyframe =
          Saved(point->reference_kf_, map.get()) ? point->reference_kf_->id() : kInvalidId;
      p.position = point->position_;
      p.normal = point->normal_;
      p.descriptor = point->descriptor_;
      p.min_distance = point->min_distance_;
      p.max_distance = point->max_distance_;
      for (const auto& [kf_id, obs] : point->observations_) {
        if (Saved(obs.keyframe, map.get())) p.observations.emplace_back(kf_id, obs.index);
      }
      p.visible = point->visible();
      p.found = point->found();
    }
  }
  return out;
}

void AtlasStorage::Restore(const MapWriteLock& lock, const AtlasRecord& record,
                           std::shared_ptr<const CameraRig> rig, Atlas* atlas) {
  atlas->RequireWriteLock(lock, "Restore");
  std::map<KeyFrameId, double> time_offsets;
  if (record.calibration) {
    for (const auto& [id, offset] : record.calibration->keyframe_time_offsets) {
      time_offsets[id] = offset;
    }
  }
  for (const auto& map : atlas->maps_) {
    PKSLAM_CHECK(map->keyframes_.empty() && map->map_points_.empty(),
                 "a map file loads into a new system only (map {} is not empty)", map->id_);
  }
  atlas->maps_.clear();
  atlas->current_ = nullptr;
  KeyFrameDatabase* database = atlas->database_.get();
  for (const MapRecord& m : record.maps) {
    auto map = std::make_unique<Map>(m.id);
    Map* map_ptr = map.get();
    map->set_database(database);
    std::map<KeyFrameId, KeyFrame*> keyframes;
    // Pass 1: the objects.
    for (const KeyFrameRecord& k : m.keyframes) {
      // The constructor is private to AtlasStorage's use; make_shared cannot reach it.
      KeyFramePtr kf(new KeyFrame(k.id, k.frame_id, k.t_ns, rig, map_ptr));
      kf->keypoints_ = FromRecords(k.keypoints);
      kf->keypoints_un_ = FromRecords(k.keypoints_undistorted);
      PKSLAM_CHECK(k.descriptors.size() == kf->keypoints_un_.size() &&
                       k.map_points.size() == kf->keypoints_un_.size(),
                   "keyframe {}: {} keypoints, {} descriptors, {} point slots", k.id,
                   kf->keypoints_un_.size(), k.descriptors.size(), k.map_points.size());
      kf->right_u_ = k.right_u;
      kf->depth_ = k.depth;
      kf->depth_sigma_ = k.depth_sigma;
      kf->descriptors_ = k.descriptors;
      kf->grid_ = FeatureGrid(kf->keypoints_un_, rig->bounds);
      kf->bow_ = BowVector::FromUnsorted(k.bow);
      kf->feature_vector_ = FeatureVector::FromPairs(k.feature_vector);
      kf->SetPose(lock, k.camera_from_world);
      kf->map_points_.assign(k.map_points.size(), nullptr);
      kf->not_erase_ = k.not_erase;
      kf->camera_from_parent_ = k.camera_from_parent;
      kf->imu_.from_previous = k.imu_from_previous;
      kf->imu_.state = k.imu_state;
      kf->imu_.prior = k.imu_prior;
      kf->imu_.time_offset_s = time_offsets.count(k.id) > 0 ? time_offsets.at(k.id) : 0.0;
      keyframes[k.id] = kf.get();
      map->keyframes_[k.id] = kf;
    }
    auto keyframe = [&](KeyFrameId id, const char* what) -> KeyFrame* {
      if (id == kInvalidId) return nullptr;
      const auto it = keyframes.find(id);
      PKSLAM_CHECK(it != keyframes.end(), "map {}: {} names keyframe {}, which is not in it",
                   m.id, what, id);
      return it->second;
    };
    for (const MapPointRecord& p : m.points) {
      auto point = std::make_shared<MapPoint>(p.id, p.position,
                                              keyframe(p.reference_keyframe, "a point"), map_ptr);
      point->first_kf_id_ = p.first_keyframe;
      point->normal_ = p.normal;
      point->descriptor_ = p.descriptor;
      point->min_distance_ = p.min_distance;
      point->max_distance_ = p.max_distance;
      point->visible_.store(p.visible);
      point->found_.store(p.found);
      for (const auto& [kf_id, index] : p.observations) {
        KeyFrame* kf = keyframe(kf_id, "an observation");
        PKSLAM_CHECK(index >= 0 && index < kf->size(),
                     "point {}: observation index {} outside keyframe {}", p.id, index, kf_id);
        point->AddObservation(lock, kf, index);
      }
      map->map_points_[p.id] = std::move(point);
    }
    // Pass 2: the links between them.
    for (const KeyFrameRecord& k : m.keyframes) {
      KeyFrame* kf = keyframes.at(k.id);
      for (std::size_t i = 0; i < k.map_points.size(); ++i) {
        if (k.map_points[i] == kInvalidId) continue;
        const auto it = map->map_points_.find(k.map_points[i]);
        PKSLAM_CHECK(it != map->map_points_.end(), "keyframe {}: point {} is not in map {}", k.id,
                     k.map_points[i], m.id);
        kf->map_points_[i] = it->second;
      }
      for (const auto& [other, weight] : k.connections) {
        kf->connections_[other] = {keyframe(other, "a covisibility edge"), weight};
      }
      kf->UpdateBestCovisibles();
      if (KeyFrame* parent = keyframe(k.parent, "a spanning-tree parent")) {
        kf->parent_ = parent;
        parent->AddChild(lock, kf);
        kf->first_connection_ = false;
      }
      for (KeyFrameId other : k.loop_edges) {
        kf->loop_edges_[other] = keyframe(other, "a loop edge");
      }
      InertialChain::Restore(kf, keyframe(k.imu_previous, "the inertial chain"),
                             keyframe(k.imu_next, "the inertial chain"));
      if (database != nullptr) database->Add(lock, kf);
    }
    map->origin_ = keyframe(m.origin, "the origin");
    map->max_kf_id_ = m.max_keyframe_id;
    map->change_index_ = m.change_index;
    map->imu_status_.imu_initialized = m.imu_initialized;
    map->imu_status_.inertial_ba1_done = m.inertial_ba1_done;
    map->imu_status_.inertial_ba2_done = m.inertial_ba2_done;
    map->imu_status_.gravity_refinement_observability = m.gravity_refinement_observability;
    map->imu_status_.imu_init_t_ns = m.imu_init_t_ns;
    for (const WorldChangeRecord& c : m.world_changes) {
      map->world_changes_.push_back({static_cast<WorldChange::Kind>(c.kind), c.rotation, c.scale});
    }
    map->applied_scale_ = m.applied_scale;
    map->world_transforms_ = m.world_transforms;
    if (m.id == record.current_map) atlas->current_ = map_ptr;
    atlas->maps_.push_back(std::move(map));
  }
  atlas->next_map_id_ = record.next_map_id;
  atlas->next_frame_id_.store(record.next_frame_id);
  atlas->next_kf_id_.store(record.next_keyframe_id);
  atlas->next_point_id_.store(record.next_point_id);
  if (atlas->current_ == nullptr) {
    if (atlas->maps_.empty()) {
      atlas->CreateNewMap(lock);
    } else {
      atlas->current_ = atlas->maps_.back().get();
    }
  }
}

}  // namespace pkslam

namespace pkslam {

CalibrationRecord ToCalibrationRecord(const RigCalibration& calibration) {
  CalibrationRecord r;
  for (const CameraModel& c : calibration.cameras) {
    r.cameras.push_back({c.width(), c.height(), c.fx(), c.fy(), c.cx(), c.cy(), c.distortion()});
  }
  r.body_from_cam0 = calibration.body_from_cam0;
  r.cam1_from_cam0 = calibration.cam1_from_cam0;
  r.time_offset_s = calibration.time_offset_s;
  for (int i = 0; i < 3; ++i) r.gyro_scale[i] = calibration.gyro_scale[i];
  for (int i = 0; i < 9; ++i) r.accel_axes[i] = calibration.accel_axes(i / 3, i % 3);
  return r;
}

RigCalibration FromCalibrationRecord(const CalibrationRecord& record) {
  RigCalibration c;
  for (const CalibrationRecord::Camera& r : record.cameras) {
    c.cameras.push_back(
        CameraModel::Pinhole(r.width, r.height, r.fx, r.fy, r.cx, r.cy, r.distortion));
  }
  c.body_from_cam0 = record.body_from_cam0;
  c.cam1_from_cam0 = record.cam1_from_cam0;
  c.time_offset_s = record.time_offset_s;
  c.gyro_scale = Eigen::Vector3d(record.gyro_scale[0], record.gyro_scale[1], record.gyro_scale[2]);
  for (int i = 0; i < 9; ++i) c.accel_axes(i / 3, i % 3) = record.accel_axes[i];
  return c;
}

}  // namespace pkslam
