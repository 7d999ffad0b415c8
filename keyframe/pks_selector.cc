#include "keyframe/pks_selector.h"

#include <cmath>

#include "core/util/error.h"
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
  PKSLAM_CHECK_OPTION(
      pairing_radius_px > 0 && pairing_max_hamming > 0 && pairing_max_hamming <= 257,
      "Keyframe.pairing", "radius {} px / Hamming {}", pairing_radius_px, pairing_max_hamming);
}

PksCompanionRules EvaluatePksCompanionRules(const SelectorInput& in, const PksOptions& o,
                                            bool close_needs_idle_mapping) {
  const Sensor s = in.sensor;
  PksCompanionRules r;
  const bool need_close = !IsMonocular(s) && in.tracked_close < o.close_tracked_max &&
                          in.untracked_close > o.close_untracked_min;
  r.close = need_close && in.inliers > 15 && (in.local_mapping_idle || !close_needs_idle_mapping);
  r.time = in.SecondsSinceLastKeyFrame() >=
           (IsInertial(s) ? o.inertial_interval_s : o.visual_interval_s);
  r.weak_mono_inertial =
      s == Sensor::kMonocularInertial && ((in.inliers > 15 && in.inliers < 75) || in.recently_lost);
  r.weak = !IsInertial(s) && o.weak_tracking_ratio > 0 &&
           in.inliers < o.weak_tracking_ratio * in.reference_tracked_points;
  return r;
}

ReasonList PksReasons(bool camera, bool forced, bool imu, const PksCompanionRules& rules) {
  ReasonList reasons;
  reasons.Add(camera, "camera");
  reasons.Add(forced, "forced");
  reasons.Add(imu, "imu");
  reasons.Add(rules.close, "close");
  reasons.Add(rules.time, "time");
  reasons.Add(rules.weak_mono_inertial, "weak-mono-inertial");
  reasons.Add(rules.weak, "weak");
  return reasons;
}

PksSelector::PksSelector(PksOptions options) : options_(options) { options_.Check(); }

void PksSelector::Reset() {
  snapshot_.clear();
  has_snapshot_ = false;
  keyframe_accel_camera_.reset();
  reference_.reset();
}

void PksSelector::OnKeyFrameInserted(const SelectorInput& input) {
  snapshot_.clear();
  reference_.reset();  // the paper takes a fresh reference after every keyframe
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(input.points.size());
  for (const auto& p : input.points) positions.push_back(p.position_world);
  const auto normals = pks::EstimateNormals(positions, options_.normal_neighbours, true);
  const SO3d camera_from_world = input.camera_from_world.so3();
  for (std::size_t i = 0; i < input.points.size(); ++i) {
    snapshot_[input.points[i].id] = {camera_from_world * normals[i]};
  }
  has_snapshot_ = true;
  keyframe_accel_camera_.reset();
  if (input.imu_since_last_frame && input.imu_since_last_frame->mean_accel_world_no_gravity) {
    keyframe_accel_camera_ =
        camera_from_world * *input.imu_since_last_frame->mean_accel_world_no_gravity;
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
  const SO3d keyframe_from_world = input.last_keyframe_camera_from_world.so3();
  for (const std::size_t i : missing)
    snapshot_[input.points[i].id] = {keyframe_from_world * normals[i]};
  has_snapshot_ = true;
}

PksSelector::Counts PksSelector::Measure(const SelectorInput& input,
                                         pks::ViewChangeDiagnostics* diagnostics) const {
  Counts c;
  const int n = options_.grid;
  c.grid.assign(n * n, 0);
  c.a = static_cast<int>(input.points.size());
  const Eigen::Vector3d center = input.camera_from_world.Inverse().translation();
  const SE3d world_from_keyframe = input.last_keyframe_camera_from_world.Inverse();
  const Eigen::Vector3d kf_center = world_from_keyframe.translation();
  for (const SelectorPoint& p : input.points) {
    const auto it = snapshot_.find(p.id);
    if (it == snapshot_.end()) continue;
    ++c.m;
    const SnapshotPoint& s = it->second;
    if (s.normal_keyframe.isZero()) continue;  // no surface estimate: no region
    // One normal and one point estimate, seen from the keyframe and from the frame.
    const Eigen::Vector3d normal = world_from_keyframe.so3() * s.normal_keyframe;
    const double kf_angle = pks::ViewAngleDeg(normal, p.position_world, kf_center, false);
    const double angle = pks::ViewAngleDeg(normal, p.position_world, center, false);
    const bool region_changed =
        pks::ConeRegion(angle, options_.region_width_deg, options_.regions) !=
        pks::ConeRegion(kf_angle, options_.region_width_deg, options_.regions);
    if (region_changed) ++c.d;
    const double change = std::abs(angle - kf_angle);
    if (diagnostics) diagnostics->Add(change, p.position_world, kf_center, center);
    if (change > options_.delta_deg) {
      ++c.grid[pks::GridCell(p.uv.x(), p.uv.y(), input.image_width, input.image_height, n)];
    }
  }
  return c;
}

bool PksSelector::CameraCriterion(const SelectorInput& input, SelectorTrace* trace) {
  // The paper's M counts every point matched between the keyframe and the current frame; the
  // snapshot taken at insertion only holds the points tracked then (the released code's
  // reading), so it is completed with points the keyframe gained since.
  if (input.points.size() > static_cast<std::size_t>(options_.normal_neighbours)) {
    ExtendSnapshot(input);
  }
  if (!has_snapshot_ ||
      input.points.size() < static_cast<std::size_t>(options_.normal_neighbours) + 1) {
    return false;  // too few points for a surface normal: no camera decision
  }
  pks::ViewChangeDiagnostics diagnostics;
  const Counts c = Measure(input, input.trace_wanted ? &diagnostics : nullptr);
  if (!reference_) reference_ = c;  // the first frame after the keyframe
  pks::TraceCounts(c, "c", trace);
  diagnostics.Fill(trace);
  const Counts& r = *reference_;
  pks::CameraRule rule;
  rule.grid = options_.grid;
  return pks::CameraCriterion(c, r, rule, trace);
}

std::optional<double> PksSelector::AccelerationChange(const SelectorInput& input) const {
  if (!input.imu_since_last_frame) return std::nullopt;
  const auto& now = input.imu_since_last_frame->mean_accel_world_no_gravity;
  if (!now || !keyframe_accel_camera_) return std::nullopt;
  const Eigen::Vector3d keyframe_accel =
      input.last_keyframe_camera_from_world.so3().Inverse() * *keyframe_accel_camera_;
  return (*now - keyframe_accel).norm();
}

SelectorDecision PksSelector::Decide(const SelectorInput& in) {
  if (auto exit = CommonSafetyExits(in, options_.imu_uninitialised_interval_s)) return *exit;
  const Eigen::Vector3d center = in.camera_from_world.Inverse().translation();
  const Eigen::Vector3d kf_center = in.last_keyframe_camera_from_world.Inverse().translation();
  if (in.keyframes_in_map > 2 && (center - kf_center).norm() < options_.min_translation_m) {
    return SelectorDecision::No("still");
  }

  SelectorTrace trace;
  const bool camera = CameraCriterion(in, &trace);
  const auto accel_change = AccelerationChange(in);
  if (accel_change) trace["delta_a"] = *accel_change;
  const bool imu =
      options_.imu_threshold > 0 && accel_change && *accel_change > options_.imu_threshold;

  // The close-point rule needs local mapping idle, as the code PKS combines with (its c3): without
  // that, realistic MH_01 stereo-inertial took 600 close keyframes (3.3/s) and lost tracking.
  const PksCompanionRules rules = EvaluatePksCompanionRules(in, options_, true);
  return DecideFromReasons(in, PksReasons(camera, false, imu, rules), std::move(trace));
}

}  // namespace pkslam
