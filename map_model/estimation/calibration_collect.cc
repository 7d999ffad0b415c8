// Collect phase of the calibration bundle adjustment.
#include "map_model/estimation/calibration_collect.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/util/error.h"
#include "map_model/estimation/bundle_collect.h"
#include "map_model/estimation/inertial_bundle_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_point.h"

namespace pkslam {
namespace {

// Keeps at most `max_per_keyframe` observations of each keyframe: an even share per cell of a
// 4x4 grid over the image, points with more observations first (ties: problem order).
void Thin(const std::vector<int>& observations_per_point, int max_per_keyframe,
          const ImageBounds& bounds, CalibrationBundleProblem* problem) {
  constexpr int kCells = 4;
  BundleProblem& visual = problem->bundle.visual;
  const int num_kf = static_cast<int>(visual.keyframes.size());
  std::vector<std::vector<int>> by_cell(static_cast<std::size_t>(num_kf * kCells * kCells));
  const double w = std::max(1.0, bounds.max_x - bounds.min_x);
  const double h = std::max(1.0, bounds.max_y - bounds.min_y);
  for (int i = 0; i < static_cast<int>(visual.observations.size()); ++i) {
    const auto& o = visual.observations[i];
    const int cx =
        std::clamp(static_cast<int>((o.uv.x() - bounds.min_x) / w * kCells), 0, kCells - 1);
    const int cy =
        std::clamp(static_cast<int>((o.uv.y() - bounds.min_y) / h * kCells), 0, kCells - 1);
    by_cell[static_cast<std::size_t>((o.keyframe_index * kCells + cy) * kCells + cx)].push_back(i);
  }
  std::vector<std::uint8_t> keep(visual.observations.size(), 0);
  for (int k = 0; k < num_kf; ++k) {
    // Round-robin over the cells, each cell's best-observed points first.
    std::array<std::vector<int>*, kCells * kCells> cells{};
    for (int c = 0; c < kCells * kCells; ++c) {
      auto& list = by_cell[static_cast<std::size_t>(k * kCells * kCells + c)];
      std::stable_sort(list.begin(), list.end(), [&](int a, int b) {
        return observations_per_point[visual.observations[a].point_index] >
               observations_per_point[visual.observations[b].point_index];
      });
      cells[c] = &list;
    }
    int taken = 0;
    for (std::size_t round = 0; taken < max_per_keyframe; ++round) {
      bool any = false;
      for (auto* list : cells) {
        if (round >= list->size() || taken >= max_per_keyframe) continue;
        keep[(*list)[round]] = 1;
        ++taken;
        any = true;
      }
      if (!any) break;
    }
  }
  std::vector<BundleProblem::ObservationState> observations;
  std::vector<CalibrationBundleProblem::RawObservation> raw;
  for (std::size_t i = 0; i < keep.size(); ++i) {
    if (!keep[i]) continue;
    observations.push_back(visual.observations[i]);
    raw.push_back(problem->raw[i]);
  }
  visual.observations = std::move(observations);
  problem->raw = std::move(raw);
}

}  // namespace

void CalibrationCollectOptions::Check() const {
  PKSLAM_CHECK_OPTION(max_observations_per_keyframe >= 0,
                      "calibration.max_observations_per_keyframe", "{}",
                      max_observations_per_keyframe);
}

Eigen::Vector3d AngularVelocityAt(const KeyFrame& kf, double window_s) {
  if (!kf.imu().from_previous || kf.imu().from_previous->steps.empty())
    return Eigen::Vector3d::Zero();
  const auto& steps = kf.imu().from_previous->steps;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double span = 0;
  for (auto it = steps.rbegin(); it != steps.rend() && span < window_s; ++it) {
    sum += it->gyro * it->dt;
    span += it->dt;
  }
  if (span <= 0) return Eigen::Vector3d::Zero();
  return sum / span - kf.imu().state.bias.gyro;
}

CalibrationBundleProblem CollectCalibrationBundle(const MapLock& lock, KeyFrame* newest,
                                                  bool inertial, const RigSetup& setup,
                                                  const RigCalibration& current,
                                                  const RigCalibration& file,
                                                  const CalibrationCollectOptions& options) {
  RequireMapLock(lock, "CollectCalibrationBundle");
  options.Check();
  CalibrationBundleProblem problem;
  problem.initial = current;
  problem.prior = file;
  if (newest == nullptr || newest->IsBad() || newest->map() == nullptr) return problem;
  const Map& map = *newest->map();
  if (inertial) {
    // The chain ends at whichever of the last 10 keyframes has the longest chain behind it: the
    // very last keyframes of a sequence may have no preintegration (the IMU log ends with the
    // images), and a chain from one of them would leave the adjustment visual-only.
    KeyFrame* end = newest;
    std::size_t longest = 0;
    int tried = 0;
    for (auto it = map.keyframes().rbegin(); it != map.keyframes().rend() && tried < 10;
         ++it, ++tried) {
      if (it->second->IsBad() || it->second->id() > newest->id()) continue;
      const std::size_t length = InertialChain::EndingAt(it->second.get(), 0).size();
      if (length > longest) {
        longest = length;
        end = it->second.get();
      }
    }
    InertialBundleOptions ba;
    problem.bundle = CollectFullInertialBundle(end, ba, /*free_tilt=*/false);
    problem.inertial = !problem.bundle.edges.empty();
  }
  if (!problem.inertial) {
    problem.bundle = {};
    problem.bundle.visual = CollectGlobalBundle(lock, map);
    problem.bundle.camera_from_body = setup.rig->body_from_camera.Inverse();
    problem.bundle.inertial.assign(problem.bundle.visual.keyframes.size(), 0);
    problem.bundle.velocities.assign(problem.bundle.visual.keyframes.size(),
                                     Eigen::Vector3d::Zero());
    problem.bundle.biases.assign(problem.bundle.visual.keyframes.size(), ImuBias{});
  }
  BundleProblem& visual = problem.bundle.visual;
  std::vector<const KeyFrame*> keyframes;
  keyframes.reserve(visual.keyframes.size());
  for (const auto& k : visual.keyframes) {
    const KeyFramePtr kf = map.KeyFrameById(k.keyframe_id);
    PKSLAM_CHECK(kf != nullptr, "calibration collect: keyframe {} left map {}", k.keyframe_id,
                 map.id());
    keyframes.push_back(kf.get());
    problem.angular_velocity.push_back(problem.inertial ? AngularVelocityAt(*kf)
                                                        : Eigen::Vector3d::Zero());
    problem.time_offset_applied.push_back(kf->imu().time_offset_s);
  }
  // The edges' copies carry no steps: the axis errors' Jacobians come from the keyframes'.
  if (options.imu_axes_jacobians) {
    for (const auto& e : problem.bundle.edges) {
      const KeyFrame& to = *keyframes[static_cast<std::size_t>(e.to)];
      const bool steps = to.imu().from_previous.has_value();
      problem.gyro_scale_jacobians.push_back(steps ? GyroScaleJacobiansOf(*to.imu().from_previous)
                                                   : GyroScaleJacobians{});
      problem.accel_axes_jacobians.push_back(steps ? AccelAxesJacobiansOf(*to.imu().from_previous)
                                                   : AccelAxesJacobians{});
    }
  }
  // Physical measurements; an observation that cannot be mapped back is dropped.
  std::vector<BundleProblem::ObservationState> observations;
  observations.reserve(visual.observations.size());
  problem.raw.reserve(visual.observations.size());
  std::vector<int> per_point(visual.points.size(), 0);
  for (const auto& o : visual.observations) {
    const KeyFrame& kf = *keyframes[o.keyframe_index];
    const cv::Point2f& raw_kp = kf.keypoints()[o.keypoint_index].pt;
    const auto raw = MakeRawMeasurement(setup, o.uv, o.u_right, o.inv_sigma2,
                                        Eigen::Vector2d(raw_kp.x, raw_kp.y));
    if (!raw) continue;
    observations.push_back(o);
    problem.raw.push_back(
        {raw->left, raw->left_whitening, raw->has_right, raw->right, raw->right_whitening});
    ++per_point[o.point_index];
  }
  visual.observations = std::move(observations);
  if (options.max_observations_per_keyframe > 0) {
    Thin(per_point, options.max_observations_per_keyframe, setup.rig->bounds, &problem);
  }
  return problem;
}

}  // namespace pkslam
