#include "keyframe/pks_selector.h"

#include <cmath>

#include "core/util/error.h"
#include "keyframe/orbslam3_selector.h"
#include "keyframe/selector_common.h"

namespace pkslam {

void PksOptions::Check() const {
  PKSLAM_CHECK_OPTION(region_width_deg > 0 && region_width_deg < 90, "Keyframe.region_width", "{}",
                      region_width_deg);
  PKSLAM_CHECK_OPTION(regions >= 2, "Keyframe.regions", "{}", regions);
  PKSLAM_CHECK_OPTION(delta_deg > 0 && delta_deg < 180, "Keyframe.delta", "{}", delta_deg);
  PKSLAM_CHECK_OPTION(grid >= 2, "Keyframe.grid", "{}", grid);
  PKSLAM_CHECK_OPTION(normal_neighbours >= 2, "Keyframe.normal_neighbours", "{}",
                      normal_neighbours);
  PKSLAM_CHECK_OPTION(min_translation_m >= 0, "Keyframe.min_translation", "{}", min_translation_m);
  PKSLAM_CHECK_OPTION(inertial_interval_s > 0 && imu_uninitialised_interval_s > 0,
                      "Keyframe.inertial_interval", "{} / {}", inertial_interval_s,
                      imu_uninitialised_interval_s);
  PKSLAM_CHECK_OPTION(visual_interval_s > 0, "Keyframe.visual_interval", "{}", visual_interval_s);
  PKSLAM_CHECK_OPTION(weak_tracking_ratio >= 0 && weak_tracking_ratio < 1,
                      "Keyframe.weak_tracking_ratio", "{}", weak_tracking_ratio);
  PKSLAM_CHECK_OPTION(forced_interval >= 0 && late_denominator_after >= 0,
                      "Keyframe.forced_interval", "{} / {}", forced_interval,
                      late_denominator_after);
}

PksSelector::PksSelector(PksOptions options, bool released)
    : options_(options), released_(released) {
  options_.Check();
}

void PksSelector::Reset() {
  snapshot_.clear();
  has_snapshot_ = false;
  keyframe_accel_.reset();
  previous_accel_.reset();
  reference_.reset();
}

void PksSelector::OnKeyFrameInserted(const SelectorInput& input) {
  snapshot_.clear();
  // The released code keeps the previous reference values until a frame with frames == 1
  // is evaluated; the paper takes a fresh reference after every keyframe.
  if (!released_) reference_.reset();
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(input.points.size());
  for (const auto& p : input.points) positions.push_back(p.position_world);
  const auto normals = pks::EstimateNormals(positions, options_.normal_neighbours, !released_);
  const Eigen::Vector3d center = input.camera_from_world.Inverse().translation();
  for (std::size_t i = 0; i < input.points.size(); ++i) {
    const double angle = pks::ViewAngleDeg(normals[i], positions[i], center, released_);
    snapshot_[input.points[i].id] = {
        normals[i], angle, pks::ConeRegion(angle, options_.region_width_deg, options_.regions)};
  }
  has_snapshot_ = true;
  keyframe_accel_.reset();
  if (input.imu_since_last_frame && input.imu_since_last_frame->mean_accel_world_no_gravity) {
    keyframe_accel_ = *input.imu_since_last_frame->mean_accel_world_no_gravity;
  }
}

void PksSelector::ExtendSnapshot(const SelectorInput& input) {
  std::vector<std::size_t> missing;
  for (std::size_t i = 0; i < input.points.size(); ++i) {
    const SelectorPoint& p = input.points[i];
    if (p.in_last_keyframe && !snapshot_.contains(p.id)) missing.push_back(i);
  }
  if (missing.empty()) return;
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(input.points.size());
  for (const auto& p : input.points) positions.push_back(p.position_world);
  // Per-frame path: normals only for the newcomers (usually a handful), not every tracked point.
  const auto normals = pks::EstimateNormals(positions, options_.normal_neighbours, true, missing);
  const Eigen::Vector3d kf_center = input.last_keyframe_camera_from_world.Inverse().translation();
  for (const std::size_t i : missing) {
    const double angle = pks::ViewAngleDeg(normals[i], positions[i], kf_center, false);
    snapshot_[input.points[i].id] = {
        normals[i], angle, pks::ConeRegion(angle, options_.region_width_deg, options_.regions)};
  }
  has_snapshot_ = true;
}

PksSelector::Counts PksSelector::Measure(const SelectorInput& input) const {
  Counts c;
  const int n = options_.grid;
  c.grid.assign(n * n, 0);
  c.a = static_cast<int>(input.points.size());
  const Eigen::Vector3d center = input.camera_from_world.Inverse().translation();
  // The released code re-estimates every normal from the current frame's tracked points.
  std::vector<Eigen::Vector3d> current_normals;
  if (released_) {
    std::vector<Eigen::Vector3d> positions;
    positions.reserve(input.points.size());
    for (const auto& p : input.points) positions.push_back(p.position_world);
    current_normals = pks::EstimateNormals(positions, options_.normal_neighbours, false);
  }
  for (std::size_t i = 0; i < input.points.size(); ++i) {
    const SelectorPoint& p = input.points[i];
    const auto it = snapshot_.find(p.id);
    if (it == snapshot_.end()) continue;
    ++c.m;
    const SnapshotPoint& s = it->second;
    const Eigen::Vector3d& normal = released_ ? current_normals[i] : s.normal;
    if (normal.isZero() || s.normal.isZero()) continue;  // no surface estimate: no region
    const double angle = pks::ViewAngleDeg(normal, p.position_world, center, released_);
    const bool region_changed =
        pks::ConeRegion(angle, options_.region_width_deg, options_.regions) != s.region;
    if (region_changed) ++c.d;
    const bool angle_changed = std::abs(angle - s.angle_deg) > options_.delta_deg;
    const bool effective = released_ ? (region_changed && angle_changed) : angle_changed;
    if (effective) {
      ++c.grid[pks::GridCell(p.uv.x(), p.uv.y(), input.image_width, input.image_height, n)];
    }
  }
  return c;
}

bool PksSelector::CameraCriterion(const SelectorInput& input, SelectorTrace* trace) {
  const int frames = input.FramesSinceLastKeyFrame();
  // The paper's M counts every point matched between the keyframe and the current frame; the
  // snapshot taken at insertion only holds the points tracked then (the released code's
  // reading), so the paper variant completes it with points the keyframe gained since.
  if (!released_ && input.points.size() > static_cast<std::size_t>(options_.normal_neighbours)) {
    ExtendSnapshot(input);
  }
  if (!has_snapshot_ ||
      input.points.size() < static_cast<std::size_t>(options_.normal_neighbours) + 1) {
    return false;  // too few points for a surface normal: no camera decision
  }
  const Counts c = Measure(input);
  // The reference frame: the first frame after the keyframe (released code: exactly the
  // frame with frames == 1; values from an earlier interval are reused if it was skipped).
  if (!reference_ || (released_ && frames == 1)) {
    if (!released_ || frames == 1) reference_ = c;
  }
  auto& t = *trace;
  t["A_c"] = c.a;
  t["M_c"] = c.m;
  t["D_c"] = c.d;
  if (!reference_) return false;
  const Counts& r = *reference_;
  t["A_r"] = r.a;
  t["M_r"] = r.m;
  t["D_r"] = r.d;

  const pks::AdaptiveThreshold th =
      pks::ComputeAdaptiveThreshold(c.a, c.m, c.d, r.a, r.m, r.d, released_);
  bool criterion1 = false;
  if (th.valid) {
    t["theta"] = th.theta;
    t["beta"] = th.beta;
    t["alpha"] = th.alpha;
    if (released_) t["gamma"] = th.gamma;
    t["Th_initial"] = th.th_initial;
    t["Th_adaptive"] = th.th_adaptive;
    criterion1 = c.d > th.th_adaptive;
    if (released_ && (frames <= 1 || c.d == 0)) criterion1 = false;
  }
  const bool late = released_ && frames > options_.late_denominator_after;
  const pks::Ecog ecog = pks::ComputeEcog(c.grid, options_.grid, late);
  bool criterion2 = false;
  if (ecog.valid) {
    t["ECOG"] = ecog.ecog;
    t["COG"] = ecog.cog;
    criterion2 = ecog.ecog > ecog.cog;
  }
  return criterion1 && criterion2;
}

std::optional<double> PksSelector::AccelerationChange(const SelectorInput& input) const {
  if (!input.imu_since_last_frame) return std::nullopt;
  if (released_) {
    if (!previous_accel_ || input.FramesSinceLastKeyFrame() <= 1) return std::nullopt;
    return (input.imu_since_last_frame->mean_accel - *previous_accel_).norm();
  }
  const auto& now = input.imu_since_last_frame->mean_accel_world_no_gravity;
  if (!now || !keyframe_accel_) return std::nullopt;
  return (*now - *keyframe_accel_).norm();
}

SelectorDecision PksSelector::Decide(const SelectorInput& in) {
  SelectorDecision decision;
  // The released code compares consecutive frame intervals: remember this one for the next.
  struct RememberAccel {
    PksSelector* self;
    const SelectorInput& in;
    ~RememberAccel() {
      if (in.imu_since_last_frame) self->previous_accel_ = in.imu_since_last_frame->mean_accel;
    }
  } remember{this, in};

  if (auto exit = CommonSafetyExits(in, options_.imu_uninitialised_interval_s)) return *exit;
  const Eigen::Vector3d center = in.camera_from_world.Inverse().translation();
  const Eigen::Vector3d kf_center = in.last_keyframe_camera_from_world.Inverse().translation();
  if (in.keyframes_in_map > 2 && (center - kf_center).norm() < options_.min_translation_m) {
    return SelectorDecision::No("still");
  }

  SelectorTrace trace;
  const bool camera = CameraCriterion(in, &trace);
  const int frames = in.FramesSinceLastKeyFrame();
  const bool forced =
      released_ && options_.forced_interval > 0 && frames == options_.forced_interval;
  const auto accel_change = AccelerationChange(in);
  if (accel_change) trace["delta_a"] = *accel_change;
  const bool imu =
      options_.imu_threshold > 0 && accel_change && *accel_change > options_.imu_threshold;

  const Sensor s = in.sensor;
  const bool need_close = !IsMonocular(s) && in.tracked_close < options_.close_tracked_max &&
                          in.untracked_close > options_.close_untracked_min;
  const bool c3 = need_close && in.inliers > 15;
  const bool c1 = IsInertial(s) ? in.SecondsSinceLastKeyFrame() >= options_.inertial_interval_s
                                : in.SecondsSinceLastKeyFrame() >= options_.visual_interval_s;
  const bool c2 =
      s == Sensor::kMonocularInertial && ((in.inliers > 15 && in.inliers < 75) || in.recently_lost);
  const bool weak = !IsInertial(s) && options_.weak_tracking_ratio > 0 &&
                    in.inliers < options_.weak_tracking_ratio * in.reference_tracked_points;

  std::string reason;
  auto add = [&reason](bool c, const char* name) {
    if (!c) return;
    if (!reason.empty()) reason += '+';
    reason += name;
  };
  add(camera, "camera");
  add(forced, "forced");
  add(imu, "imu");
  add(c3, "close");
  add(c1, "time");
  add(c2, "weak-mono-inertial");
  add(weak, "weak");
  if (reason.empty()) {
    decision.reason = "no";
    decision.trace = std::move(trace);
    return decision;
  }
  decision = AcceptIfMappingCanTakeIt(in, reason);
  decision.trace = std::move(trace);
  return decision;
}

}  // namespace pkslam
