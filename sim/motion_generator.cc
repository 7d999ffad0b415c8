#include "sim/motion_generator.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "core/util/error.h"
#include "sim/random.h"

namespace pkslam::sim {

MotionLevel ParseMotionLevel(const std::string& name) {
  if (name == "easy") return MotionLevel::kEasy;
  if (name == "medium") return MotionLevel::kMedium;
  if (name == "difficult") return MotionLevel::kDifficult;
  throw OptionError("motion must be easy, medium or difficult, got '" + name + "'");
}

std::string MotionLevelName(MotionLevel level) {
  switch (level) {
    case MotionLevel::kEasy:
      return "easy";
    case MotionLevel::kMedium:
      return "medium";
    case MotionLevel::kDifficult:
      return "difficult";
  }
  return "?";
}

MotionLevelParams ParamsFor(MotionLevel level) {
  switch (level) {
    case MotionLevel::kEasy:
      return {0.4, 15.0, 1.0};
    case MotionLevel::kMedium:
      return {0.9, 35.0, 0.6};
    case MotionLevel::kDifficult:
      return {1.5, 70.0, 0.4};
  }
  return {0.9, 35.0, 0.6};
}

void MotionOptions::Check() const {
  PKSLAM_CHECK_OPTION(duration_s > 0.0 && duration_s <= 3600.0, "motion.duration_s", "{}",
                      duration_s);
  PKSLAM_CHECK_OPTION(rest_s >= 0.0 && rest_s < duration_s, "motion.rest_s", "{}", rest_s);
  PKSLAM_CHECK_OPTION(clearance_m >= 0.0 && wall_clearance_m >= 0.0, "motion.clearance",
                      "must be >= 0");
  PKSLAM_CHECK_OPTION(min_height_m < max_height_m, "motion.height", "{} >= {}", min_height_m,
                      max_height_m);
  PKSLAM_CHECK_OPTION(min_view_m > 0.0 && max_view_m > min_view_m, "motion.view", "[{}, {}]",
                      min_view_m, max_view_m);
}

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

class Planner {
 public:
  Planner(const Scene& scene, const MotionOptions& o, Rng* rng) : scene_(scene), o_(o), rng_(rng) {
    const Shape* room = scene.Room();
    PKSLAM_CHECK(room != nullptr, "random motion needs a scene with a room");
    const Eigen::Vector3d c = room->center.cast<double>();
    const Eigen::Vector3d h = room->half.cast<double>();
    lo_ = c - h;
    hi_ = c + h;
    lo_.head<2>().array() += o.wall_clearance_m;
    hi_.head<2>().array() -= o.wall_clearance_m;
    const double floor = c.z() - h.z();
    lo_.z() = floor + o.min_height_m;
    hi_.z() = std::min(floor + o.max_height_m, c.z() + h.z() - o.wall_clearance_m);
    PKSLAM_CHECK((hi_ - lo_).minCoeff() > 0.2, "room too small for the requested clearances");
  }

  bool Free(const Eigen::Vector3d& p) const {
    if ((p.array() < lo_.array()).any() || (p.array() > hi_.array()).any()) return false;
    return scene_.ObjectClearance(p.cast<float>()) > o_.clearance_m + 0.2;
  }

  bool SegmentFree(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    for (int i = 1; i <= 8; ++i) {
      if (!Free(a + (b - a) * (i / 8.0))) return false;
    }
    return true;
  }

  Eigen::Vector3d RandomFreePoint() const {
    for (int attempt = 0; attempt < 5000; ++attempt) {
      Eigen::Vector3d p;  // one draw per statement (argument order is unspecified)
      for (int k = 0; k < 3; ++k) p[k] = rng_->Uniform(lo_[k], hi_[k]);
      if (Free(p)) return p;
    }
    throw Error("no free space for the camera in the scene (reduce the clearance)");
  }

  // Distance along `dir` to the first surface (infinity when none).
  double ViewDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& dir) const {
    Hit hit;
    if (!scene_.Intersect(p.cast<float>(), dir.cast<float>(), 1e3f, &hit)) {
      return std::numeric_limits<double>::infinity();
    }
    return hit.t;
  }

  const Eigen::Vector3d& lo() const { return lo_; }
  const Eigen::Vector3d& hi() const { return hi_; }

 private:
  const Scene& scene_;
  const MotionOptions& o_;
  Rng* rng_;
  Eigen::Vector3d lo_;
  Eigen::Vector3d hi_;
};

Eigen::Vector3d Direction(double yaw, double pitch) {
  return {std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch)};
}

// Camera orientation (x right, y down, z forward) looking along (yaw, pitch) with roll.
SO3d CameraRotation(double yaw, double pitch, double roll) {
  const Eigen::Vector3d f = Direction(yaw, pitch);
  const Eigen::Vector3d right = f.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = f.cross(right);
  Eigen::Matrix3d r;
  r.col(0) = right;
  r.col(1) = down;
  r.col(2) = f;
  return SO3d(r) * SO3d::Exp(Eigen::Vector3d(0, 0, roll));
}

}  // namespace

SplineTrajectory GenerateMotion(const Scene& scene, const MotionOptions& options,
                                const SE3d& body_from_camera, std::uint64_t seed,
                                std::int64_t t0_ns) {
  options.Check();
  const MotionLevelParams level = ParamsFor(options.level);
  Rng rng(DeriveSeed(seed, 0x4D4F54494F4E));
  const Planner planner(scene, options, &rng);
  const double h = level.knot_s;
  const auto h_ns = static_cast<std::int64_t>(std::llround(h * 1e9));
  const KnotGrid grid = KnotGrid::Covering(
      t0_ns, t0_ns + static_cast<std::int64_t>(std::llround(options.duration_s * 1e9)), h_ns);

  // Positions: rest, then a heading-persistent random walk through free space.
  const int n_pos = PositionSpline6::NumControl(grid);
  const int rest_knots = static_cast<int>(std::ceil(options.rest_s / h));
  std::vector<Eigen::Vector3d> pos(n_pos);
  Eigen::Vector3d p = planner.RandomFreePoint();
  double heading = rng.Uniform(0.0, 2.0 * std::numbers::pi);
  double climb = 0.0;
  for (int j = 0; j < n_pos; ++j) {
    if (j < rest_knots + kPositionOrder - 1) {
      pos[j] = p;
      continue;
    }
    const int moving = j - (rest_knots + kPositionOrder - 1);
    const double ramp = std::min(1.0, (moving + 1) / 4.0);  // smooth take-off
    // 1.17: the spline cuts the random walk's corners, losing ~15% of the control polygon's
    // length (measured over 60 s flights at every level).
    const double step = 1.17 * level.speed_mps * h * ramp * rng.Uniform(0.75, 1.25);
    bool placed = false;
    for (int attempt = 0; attempt < 40 && !placed; ++attempt) {
      // Small turns first; widen the search when blocked, biased to the room centre.
      const double spread = (0.35 + 0.12 * attempt) * (1.0 + level.angular_rate_dps / 35.0);
      double cand_heading = heading + rng.Normal(0.0, spread * 0.5);
      if (attempt >= 20) {
        const Eigen::Vector3d to_centre = 0.5 * (planner.lo() + planner.hi()) - p;
        cand_heading = std::atan2(to_centre.y(), to_centre.x()) + rng.Normal(0.0, 0.6);
      }
      const double cand_climb = std::clamp(0.7 * climb + rng.Normal(0.0, 0.25), -0.5, 0.5);
      const Eigen::Vector3d next = p + step * Direction(cand_heading, cand_climb);
      if (planner.SegmentFree(p, next)) {
        p = next;
        heading = cand_heading;
        climb = cand_climb;
        placed = true;
      }
    }
    if (!placed) climb = 0.0;  // hover in place this knot; try again from here
    pos[j] = p;
  }
  PositionSpline6 position(grid, pos);

  // Orientation: rate-limited random yaw/pitch/roll steered to keep a surface in view.
  const int n_rot = RotationSpline4::NumControl(grid);
  const SO3d camera_from_body = body_from_camera.so3().Inverse();
  std::vector<SO3d> rot(n_rot);
  const double rate = level.angular_rate_dps * kDeg;
  double yaw = heading;
  double pitch = -10.0 * kDeg;
  double roll = 0.0;
  double yaw_rate = 0.0;
  {
    // Initial view: the yaw with the best view distance.
    const Eigen::Vector3d p0 = pos.front();
    double best = -1.0;
    for (int k = 0; k < 36; ++k) {
      const double y = k * 10.0 * kDeg;
      const double d = planner.ViewDistance(p0, Direction(y, pitch));
      const double score = d >= options.min_view_m && d <= options.max_view_m
                               ? 10.0 - std::abs(d - 3.0)
                               : -std::abs(d - 3.0);
      if (score > best) {
        best = score;
        yaw = y;
      }
    }
  }
  for (int j = 0; j < n_rot; ++j) {
    const std::int64_t tj = grid.t0_ns + (j - (kRotationOrder - 2) / 2) * h_ns;
    const Eigen::Vector3d pj = position.Evaluate(std::clamp(tj, grid.t0_ns, grid.end_ns()));
    if (j >= rest_knots + kRotationOrder - 1) {
      // Yaw rate: a mean-reverting random process with spread ~ the level's angular rate.
      yaw_rate = 0.6 * yaw_rate + rng.Normal(0.0, 1.25 * rate);
      yaw_rate = std::clamp(yaw_rate, -2.0 * rate, 2.0 * rate);
      double cand_yaw = yaw + yaw_rate * h;
      const double cand_pitch =
          std::clamp(pitch + rng.Normal(0.0, 0.35 * rate * h), -35.0 * kDeg, 12.0 * kDeg);
      // Steer: if the view is too close or too far, take the nearest yaw that is fine.
      auto good = [&](double y) {
        const double d = planner.ViewDistance(pj, Direction(y, cand_pitch));
        return d >= options.min_view_m && d <= options.max_view_m;
      };
      if (!good(cand_yaw)) {
        for (int k = 1; k <= 18; ++k) {
          const double step = k * 10.0 * kDeg * (yaw_rate >= 0.0 ? 1.0 : -1.0);
          if (good(cand_yaw + step)) {
            cand_yaw += step;
            break;
          }
          if (good(cand_yaw - step)) {
            cand_yaw -= step;
            break;
          }
        }
        // Turning towards the fix is bounded by twice the level's rate.
        const double max_turn = 2.0 * rate * h;
        cand_yaw = yaw + std::clamp(cand_yaw - yaw, -max_turn, max_turn);
        yaw_rate = (cand_yaw - yaw) / h;
      }
      yaw = cand_yaw;
      pitch = cand_pitch;
      roll = std::clamp(0.7 * roll + rng.Normal(0.0, 0.15 * rate * h), -8.0 * kDeg, 8.0 * kDeg);
    }
    // world_from_body = world_from_camera * camera_from_body.
    rot[j] = CameraRotation(yaw, pitch, roll) * camera_from_body;
  }
  RotationSpline4 rotation(grid, rot);
  return SplineTrajectory(std::move(position), std::move(rotation));
}

}  // namespace pkslam::sim
