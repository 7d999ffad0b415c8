#include "keyframe/pks_released_selector.h"

#include <cmath>
#include <unordered_map>
#include <unordered_set>

#include "keyframe/selector_common.h"

namespace pkslam {
namespace {

// Keypoints of the frame bucketed by pixel cell, for the +-r window search of the pairing.
class PixelBuckets {
 public:
  PixelBuckets(const SelectorInput& input, const std::vector<std::size_t>& entries, double cell)
      : cell_(cell) {
    for (std::size_t e = 0; e < entries.size(); ++e) {
      const Eigen::Vector2d& uv = input.points[entries[e]].uv;
      buckets_[Key(Cell(uv.x()), Cell(uv.y()))].push_back(e);
    }
  }
  // Entries whose keypoint lies strictly inside the window |du| < r, |dv| < r, in ascending
  // keypoint order.
  std::vector<std::size_t> Near(const SelectorInput& input, const std::vector<std::size_t>& entries,
                                const Eigen::Vector2d& uv, double r) const {
    std::vector<std::size_t> out;
    for (long x = Cell(uv.x() - r); x <= Cell(uv.x() + r); ++x) {
      for (long y = Cell(uv.y() - r); y <= Cell(uv.y() + r); ++y) {
        const auto it = buckets_.find(Key(x, y));
        if (it == buckets_.end()) continue;
        for (const std::size_t e : it->second) {
          const Eigen::Vector2d d = input.points[entries[e]].uv - uv;
          if (std::abs(d.x()) < r && std::abs(d.y()) < r) out.push_back(e);
        }
      }
    }
    std::sort(out.begin(), out.end(), [&](std::size_t a, std::size_t b) {
      return input.points[entries[a]].keypoint_index < input.points[entries[b]].keypoint_index;
    });
    return out;
  }

 private:
  long Cell(double v) const { return static_cast<long>(std::floor(v / cell_)); }
  static long long Key(long x, long y) {
    return (static_cast<long long>(x) << 32) ^ (y & 0xffffffff);
  }
  double cell_;
  std::unordered_map<long long, std::vector<std::size_t>> buckets_;
};

}  // namespace

PksReleasedSelector::PksReleasedSelector(PksOptions options) : options_(options) {
  options_.Check();
}

void PksReleasedSelector::Reset() {
  snapshot_.clear();
  reference_.reset();
  previous_accel_.reset();
}

PksReleasedSelector::View PksReleasedSelector::MakeView(const SelectorInput& input,
                                                        bool with_normals) const {
  View v;
  std::unordered_set<MapPointId> seen;
  for (std::size_t i = 0; i < input.points.size(); ++i) {
    if (seen.insert(input.points[i].id).second) v.point.push_back(i);
  }
  if (!with_normals) return v;
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(v.point.size());
  for (const std::size_t i : v.point) positions.push_back(input.points[i].position_world);
  v.normal = pks::EstimateNormals(positions, options_.normal_neighbours, false);
  const Eigen::Vector3d center = input.camera_from_world.Inverse().translation();
  for (std::size_t e = 0; e < v.point.size(); ++e) {
    const double angle = pks::ViewAngleDeg(v.normal[e], positions[e], center, true);
    v.angle_deg.push_back(angle);
    v.region.push_back(pks::ConeRegion(angle, options_.region_width_deg, options_.regions));
  }
  return v;
}

void PksReleasedSelector::OnKeyFrameInserted(const SelectorInput& input) {
  snapshot_.clear();
  if (input.points.size() <= static_cast<std::size_t>(options_.normal_neighbours)) return;
  const View v = MakeView(input, true);
  for (std::size_t e = 0; e < v.point.size(); ++e) {
    const SelectorPoint& p = input.points[v.point[e]];
    snapshot_.push_back({p.id, p.position_world, *p.map_point_descriptor, v.normal[e],
                         v.angle_deg[e], v.region[e]});
  }
}

PksReleasedSelector::Counts PksReleasedSelector::Measure(
    const SelectorInput& input, pks::ViewChangeDiagnostics* diagnostics) const {
  const int n = options_.grid;
  Counts c;
  c.grid.assign(n * n, 0);
  const View v = MakeView(input, !options_.frozen_normals);
  c.a = static_cast<int>(v.point.size());
  const SE3d& tcw = input.camera_from_world;
  const Eigen::Vector3d center = tcw.Inverse().translation();
  const Eigen::Vector3d kf_center = input.last_keyframe_camera_from_world.Inverse().translation();
  const ImageBounds& b = input.bounds;
  auto project = [&](const Eigen::Vector3d& world) -> std::optional<Eigen::Vector2d> {
    const Eigen::Vector3d x = tcw * world;
    if (x.z() < 0) return std::nullopt;
    return Eigen::Vector2d(input.fx * x.x() / x.z() + input.cx,
                           input.fy * x.y() / x.z() + input.cy);
  };
  const PixelBuckets buckets(input, v.point, options_.pairing_radius_px);
  std::unordered_map<MapPointId, std::size_t> entry_of_id;
  if (options_.identity_pairing) {
    for (std::size_t e = 0; e < v.point.size(); ++e) entry_of_id[input.points[v.point[e]].id] = e;
  }

  for (const SnapshotPoint& s : snapshot_) {
    std::optional<std::size_t> paired;
    if (options_.identity_pairing) {
      if (const auto it = entry_of_id.find(s.id); it != entry_of_id.end()) paired = it->second;
    } else {
      const auto uv = project(s.position);
      if (!uv || uv->x() < b.min_x || uv->x() > b.max_x || uv->y() < b.min_y || uv->y() > b.max_y) {
        continue;
      }
      int best = 257;
      for (const std::size_t e : buckets.Near(input, v.point, *uv, options_.pairing_radius_px)) {
        const int d = HammingDistance(*input.points[v.point[e]].map_point_descriptor, s.descriptor);
        if (d < best) {
          best = d;
          paired = e;
        }
      }
      if (best >= options_.pairing_max_hamming) paired.reset();
    }
    if (!paired) continue;
    ++c.m;
    const SelectorPoint& p = input.points[v.point[*paired]];
    double angle = 0;
    int region = 0;
    if (options_.frozen_normals) {
      angle = pks::ViewAngleDeg(s.normal, p.position_world, center, true);
      region = pks::ConeRegion(angle, options_.region_width_deg, options_.regions);
    } else {
      angle = v.angle_deg[*paired];
      region = v.region[*paired];
    }
    const double change = std::abs(angle - s.angle_deg);
    if (diagnostics) diagnostics->Add(change, p.position_world, kf_center, center);
    if (region == s.region) continue;
    ++c.d;
    if (change <= options_.delta_deg) continue;
    if (const auto xy = project(p.position_world)) {
      if (const auto cell =
              pks::StrictGridCell(xy->x(), xy->y(), b.min_x, b.max_x, b.min_y, b.max_y, n)) {
        ++c.grid[*cell];
      }
    }
  }
  return c;
}

bool PksReleasedSelector::CameraCriterion(const SelectorInput& input, SelectorTrace* trace) {
  const int frames = input.FramesSinceLastKeyFrame();
  if (snapshot_.empty() ||
      input.points.size() <= static_cast<std::size_t>(options_.normal_neighbours)) {
    return false;  // the released code needs 5 neighbours per point
  }
  pks::ViewChangeDiagnostics diagnostics;
  const Counts c = Measure(input, input.trace_wanted ? &diagnostics : nullptr);
  pks::TraceCounts(c, "c", trace);
  diagnostics.Fill(trace);
  // Early return before the reference is taken: an earlier interval's reference survives.
  if (c.d == 0 || c.m == 0) return false;
  if (frames == 1) reference_ = c;
  if (!reference_) return false;  // the released code's zero statics give NaN: no keyframe
  const Counts& r = *reference_;
  pks::CameraRule rule;
  rule.released = true;
  rule.late_denominator = frames > options_.late_denominator_after;
  rule.criterion1_allowed = frames > 1;
  rule.grid = options_.grid;
  return pks::CameraCriterion(c, r, rule, trace);
}

SelectorDecision PksReleasedSelector::Decide(const SelectorInput& in) {
  // The IMU rule compares consecutive frame intervals: remember this one for the next.
  struct RememberAccel {
    PksReleasedSelector* self;
    const SelectorInput& in;
    ~RememberAccel() {
      if (in.imu_since_last_frame) self->previous_accel_ = in.imu_since_last_frame->mean_accel;
    }
  } remember{this, in};

  if (auto exit = CommonSafetyExits(in, options_.imu_uninitialised_interval_s)) return *exit;
  if (in.local_mapping_initializing && options_.no_keyframe_while_imu_initialises) {
    return SelectorDecision::No("imu-initialising");
  }
  if (in.slow_motion_before_refinement) return SelectorDecision::No("slow-motion");
  const Eigen::Vector3d center = in.camera_from_world.Inverse().translation();
  const Eigen::Vector3d kf_center = in.last_keyframe_camera_from_world.Inverse().translation();
  if (in.keyframes_in_map > 2 && (center - kf_center).norm() < options_.min_translation_m) {
    return SelectorDecision::No("still");
  }

  const int frames = in.FramesSinceLastKeyFrame();
  SelectorTrace trace;
  const bool forced = options_.forced_interval > 0 && frames == options_.forced_interval;
  // The released code returns at the forced keyframe before it measures anything.
  const bool camera = !forced && CameraCriterion(in, &trace);
  std::optional<double> accel_change;
  if (in.imu_since_last_frame && previous_accel_ && frames > 1) {
    accel_change = (in.imu_since_last_frame->mean_accel - *previous_accel_).norm();
    trace["delta_a"] = *accel_change;
  }
  const bool imu =
      options_.imu_threshold > 0 && accel_change && *accel_change > options_.imu_threshold;

  // The close-point rule needs local mapping idle; c1 is the released code's inertial timer;
  // visual-only sensors (which it never ran) get the paper selector's interval and
  // weak-tracking rules, pkslam's additions.
  const PksCompanionRules rules = EvaluatePksCompanionRules(in, options_, true);
  return DecideFromReasons(in, PksReasons(camera, forced, imu, rules), std::move(trace));
}

}  // namespace pkslam
