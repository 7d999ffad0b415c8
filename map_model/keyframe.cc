#include "map_model/keyframe.h"

#include <algorithm>

#include "core/sensor/depth_uncertainty.h"
#include "core/util/error.h"
#include "map_model/frame.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/recalibrate_features.h"

namespace pkslam {
namespace {

// Covisibility edges need at least this many shared points (ORB-SLAM's threshold).
constexpr int kCovisibilityThreshold = 15;

// Sort by weight descending, then id ascending (deterministic, unlike pointer order).
bool HeavierFirst(const std::pair<int, KeyFrame*>& a, const std::pair<int, KeyFrame*>& b) {
  if (a.first != b.first) return a.first > b.first;
  return a.second->id() < b.second->id();
}

}  // namespace

KeyFrame::KeyFrame(KeyFrameId id, const Frame& frame, Map* map)
    : id_(id),
      frame_id_(frame.id()),
      t_ns_(frame.t_ns()),
      rig_(frame.rig_ptr()),
      map_(map),
      keypoints_(frame.keypoints()),
      keypoints_un_(frame.keypoints_undistorted()),
      right_u_(frame.right_u()),
      depth_(frame.depth()),
      depth_sigma_(frame.depth_sigma()),
      descriptors_(frame.descriptors()),
      grid_(frame.grid()),
      bow_(frame.bow()),
      feature_vector_(frame.feature_vector()),
      map_points_(frame.map_points) {
  if (frame.HasPose()) Place(frame.camera_from_world());
  imu_.time_offset_s = frame.imu.time_offset_s;
}

KeyFrame::KeyFrame(KeyFrameId id, FrameId frame_id, std::int64_t t_ns,
                   std::shared_ptr<const CameraRig> rig, Map* map)
    : id_(id), frame_id_(frame_id), t_ns_(t_ns), rig_(std::move(rig)), map_(map) {}

void KeyFrame::Recalibrate(const MapWriteLock& lock, std::shared_ptr<const CameraRig> rig,
                           const RigWarp& warp, const SE3d& new_from_old) {
  RequireWriteLock(lock, "KeyFrame::Recalibrate");
  if (bad_) {
    camera_from_parent_ = new_from_old * camera_from_parent_ * new_from_old.Inverse();
  }
  Place(new_from_old * camera_from_world_);
  rig_ = std::move(rig);
  if (bad_ || keypoints_un_.empty()) return;
  RecalibrateFeatures(*rig_, warp, &keypoints_, &keypoints_un_, &right_u_, &depth_);
  grid_ = FeatureGrid(keypoints_un_, rig_->bounds);
}

double KeyFrame::DisparityInformation(int i) const {
  if (depth_sigma_.empty() || !HasDepth(i)) return 0.0;
  return pkslam::DisparityInformation(rig_->bf, depth_[i], depth_sigma_[i]);
}

std::optional<Eigen::Vector3d> KeyFrame::UnprojectStereo(int i) const {
  if (!HasDepth(i)) return std::nullopt;
  const double z = depth_[i];
  const cv::Point2f& p = keypoints_un_[i].pt;
  const Eigen::Vector3d p_camera((p.x - rig_->cx) * z * rig_->inv_fx,
                                 (p.y - rig_->cy) * z * rig_->inv_fy, z);
  return world_from_camera_ * p_camera;
}

void KeyFrame::SetPose(const MapWriteLock& lock, const SE3d& camera_from_world) {
  RequireWriteLock(lock, "KeyFrame::SetPose");
  Place(camera_from_world);
}

void KeyFrame::Place(const SE3d& camera_from_world) {
  camera_from_world_ = camera_from_world;
  world_from_camera_ = camera_from_world.Inverse();
}

double KeyFrame::SceneDepthQuantile(double q) const {
  std::vector<double> depths;
  depths.reserve(map_points_.size());
  const Eigen::Vector3d r_z = camera_from_world_.RotationMatrix().row(2).transpose();
  const double t_z = camera_from_world_.translation().z();
  for (const auto& mp : map_points_) {
    if (mp && !mp->IsBad()) depths.push_back(r_z.dot(mp->position()) + t_z);
  }
  if (depths.empty()) return -1.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(depths.size() - 1));
  std::nth_element(depths.begin(), depths.begin() + static_cast<std::ptrdiff_t>(k), depths.end());
  return depths[k];
}

void KeyFrame::AddMapPoint(const MapWriteLock& lock, const MapPointPtr& point, int index) {
  RequireWriteLock(lock, "KeyFrame::AddMapPoint");
  map_points_[index] = point;
}

void KeyFrame::EraseMapPointMatch(const MapWriteLock& lock, int index) {
  RequireWriteLock(lock, "KeyFrame::EraseMapPointMatch");
  map_points_[index].reset();
}

void KeyFrame::EraseMapPointMatch(const MapWriteLock& lock, const MapPoint* point) {
  RequireWriteLock(lock, "KeyFrame::EraseMapPointMatch");
  const int index = point->IndexInKeyFrame(this);
  if (index >= 0 && map_points_[index].get() == point) map_points_[index].reset();
}

void KeyFrame::ReplaceMapPointMatch(const MapWriteLock& lock, int index, const MapPointPtr& point) {
  RequireWriteLock(lock, "KeyFrame::ReplaceMapPointMatch");
  map_points_[index] = point;
}

std::vector<MapPointPtr> KeyFrame::GoodMapPoints() const {
  std::vector<MapPointPtr> out;
  out.reserve(map_points_.size());
  for (const auto& mp : map_points_) {
    if (mp && !mp->IsBad()) out.push_back(mp);
  }
  return out;
}

int KeyFrame::TrackedMapPoints(int min_observations) const {
  int n = 0;
  for (const auto& mp : map_points_) {
    if (mp && !mp->IsBad() && mp->NumObservations() >= min_observations) ++n;
  }
  return n;
}

void KeyFrame::UpdateConnections(const MapWriteLock& lock) {
  RequireWriteLock(lock, "KeyFrame::UpdateConnections");
  std::map<KeyFrameId, std::pair<KeyFrame*, int>> counter;
  for (const auto& mp : map_points_) {
    if (!mp || mp->IsBad()) continue;
    for (const auto& [kf_id, obs] : mp->observations()) {
      if (kf_id == id_ || obs.keyframe->IsBad()) continue;
      auto& entry = counter[kf_id];
      entry.first = obs.keyframe;
      ++entry.second;
    }
  }
  if (counter.empty()) return;

  std::vector<std::pair<int, KeyFrame*>> edges;
  std::pair<int, KeyFrame*> best{0, nullptr};
  for (const auto& [kf_id, entry] : counter) {
    const auto [kf, weight] = entry;
    if (weight > best.first) best = {weight, kf};
    if (weight >= kCovisibilityThreshold) {
      edges.emplace_back(weight, kf);
      kf->AddConnection(lock, this, weight);
    }
  }
  // Always keep at least the strongest link so no keyframe floats free.
  if (edges.empty()) {
    edges.push_back(best);
    best.second->AddConnection(lock, this, best.first);
  }
  std::sort(edges.begin(), edges.end(), HeavierFirst);

  connections_ = std::move(counter);
  ordered_connected_.clear();
  ordered_weights_.clear();
  for (const auto& [weight, kf] : edges) {
    ordered_connected_.push_back(kf);
    ordered_weights_.push_back(weight);
  }
  if (first_connection_ && map_ != nullptr && map_->origin() != this) {
    parent_ = ordered_connected_.front();
    parent_->AddChild(lock, this);
    first_connection_ = false;
  }
}

void KeyFrame::AddConnection(const MapWriteLock& lock, KeyFrame* kf, int weight) {
  RequireWriteLock(lock, "KeyFrame::AddConnection");
  auto& entry = connections_[kf->id()];
  if (entry.first == kf && entry.second == weight) return;
  entry = {kf, weight};
  UpdateBestCovisibles();
}

void KeyFrame::EraseConnection(const MapWriteLock& lock, KeyFrame* kf) {
  RequireWriteLock(lock, "KeyFrame::EraseConnection");
  if (connections_.erase(kf->id()) > 0) UpdateBestCovisibles();
}

void KeyFrame::UpdateBestCovisibles() {
  std::vector<std::pair<int, KeyFrame*>> edges;
  edges.reserve(connections_.size());
  for (const auto& [id, entry] : connections_) edges.emplace_back(entry.second, entry.first);
  std::sort(edges.begin(), edges.end(), HeavierFirst);
  ordered_connected_.clear();
  ordered_weights_.clear();
  for (const auto& [weight, kf] : edges) {
    ordered_connected_.push_back(kf);
    ordered_weights_.push_back(weight);
  }
}

int KeyFrame::Weight(const KeyFrame* kf) const {
  auto it = connections_.find(kf->id());
  return it == connections_.end() ? 0 : it->second.second;
}

std::vector<KeyFrame*> KeyFrame::BestCovisibles(int n) const {
  const auto count =
      std::min<std::size_t>(static_cast<std::size_t>(std::max(n, 0)), ordered_connected_.size());
  return {ordered_connected_.begin(), ordered_connected_.begin() + static_cast<long>(count)};
}

std::vector<KeyFrame*> KeyFrame::CovisiblesWithWeightAtLeast(int weight) const {
  std::vector<KeyFrame*> out;
  for (std::size_t i = 0; i < ordered_connected_.size() && ordered_weights_[i] >= weight; ++i) {
    out.push_back(ordered_connected_[i]);
  }
  return out;
}

std::vector<KeyFrame*> KeyFrame::ConnectedKeyFrames() const {
  std::vector<KeyFrame*> out;
  out.reserve(connections_.size());
  for (const auto& [id, entry] : connections_) out.push_back(entry.first);
  return out;
}

void KeyFrame::ChangeParent(const MapWriteLock& lock, KeyFrame* parent) {
  RequireWriteLock(lock, "KeyFrame::ChangeParent");
  if (parent == this) return;  // never make a keyframe its own parent
  parent_ = parent;
  parent->AddChild(lock, this);
}

void KeyFrame::AddChild(const MapWriteLock& lock, KeyFrame* kf) {
  RequireWriteLock(lock, "KeyFrame::AddChild");
  children_[kf->id()] = kf;
}
void KeyFrame::EraseChild(const MapWriteLock& lock, KeyFrame* kf) {
  RequireWriteLock(lock, "KeyFrame::EraseChild");
  children_.erase(kf->id());
}
void KeyFrame::AddLoopEdge(const MapWriteLock& lock, KeyFrame* kf) {
  RequireWriteLock(lock, "KeyFrame::AddLoopEdge");
  not_erase_ = true;
  loop_edges_[kf->id()] = kf;
}

void KeyFrame::SetNotErase(const MapWriteLock& lock) {
  RequireWriteLock(lock, "KeyFrame::SetNotErase");
  not_erase_ = true;
}

bool KeyFrame::SetErase(const MapWriteLock& lock) {
  RequireWriteLock(lock, "KeyFrame::SetErase");
  if (!loop_edges_.empty()) return false;  // loop keyframes stay for the essential graph
  not_erase_ = false;
  if (to_be_erased_) {
    SetBad(lock);
    return true;
  }
  return false;
}

KeyFrameImu& KeyFrame::mutable_imu(const MapWriteLock& lock) {
  PKSLAM_CHECK(lock.owns_lock(),
               "keyframe {}: inertial data changed without the Atlas's write lock", id_);
  return imu_;
}

void KeyFrame::SetBad(const MapWriteLock& lock) {
  RequireWriteLock(lock, "KeyFrame::SetBad");
  if (bad_) return;
  if (map_ != nullptr && map_->origin() == this) return;
  if (not_erase_) {
    to_be_erased_ = true;
    return;
  }
  for (const auto& [id, entry] : connections_) entry.first->EraseConnection(lock, this);
  for (std::size_t i = 0; i < map_points_.size(); ++i) {
    if (map_points_[i]) {
      const MapPointPtr mp = map_points_[i];  // EraseObservation may clear our slot
      mp->EraseObservation(lock, this);
    }
  }
  connections_.clear();
  ordered_connected_.clear();
  ordered_weights_.clear();

  // Re-attach the children: each picks the covisible candidate it shares most points with,
  // starting from our parent and growing the candidate set as children get re-attached.
  std::map<KeyFrameId, KeyFrame*> candidates;
  if (parent_ != nullptr) candidates[parent_->id()] = parent_;
  auto orphans = children_;
  while (!orphans.empty()) {
    KeyFrame* best_child = nullptr;
    KeyFrame* best_parent = nullptr;
    int best_weight = -1;
    for (const auto& [child_id, child] : orphans) {
      if (child->IsBad()) continue;
      for (KeyFrame* connected : child->CovisiblesByWeight()) {
        if (candidates.count(connected->id()) == 0) continue;
        const int w = child->Weight(connected);
        if (w > best_weight) {
          best_weight = w;
          best_child = child;
          best_parent = connected;
        }
      }
    }
    if (best_child == nullptr) break;
    best_child->ChangeParent(lock, best_parent);
    candidates[best_child->id()] = best_child;
    orphans.erase(best_child->id());
  }
  // Children without a covisible candidate hang from our parent.
  for (const auto& [child_id, child] : orphans) {
    if (parent_ != nullptr) child->ChangeParent(lock, parent_);
  }
  children_.clear();
  if (parent_ != nullptr) {
    parent_->EraseChild(lock, this);
    camera_from_parent_ = camera_from_world_ * parent_->world_from_camera();
  }
  bad_ = true;
  ReleaseFeatures();
  if (map_ != nullptr) map_->RetireKeyFrame(lock, this);
}

void KeyFrame::ReleaseFeatures() {
  // A retired keyframe keeps only its pose chain; drop the bulky data.
  std::fill(map_points_.begin(), map_points_.end(), nullptr);
  descriptors_.clear();
  descriptors_.shrink_to_fit();
  keypoints_.clear();
  keypoints_.shrink_to_fit();
  grid_ = FeatureGrid();
  bow_ = BowVector();
  feature_vector_ = FeatureVector();
}

}  // namespace pkslam
