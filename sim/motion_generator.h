// Random smooth flights inside a scene at three difficulty levels. Positions: a quintic
// B-spline whose control points random-walk through free space (clear of objects and walls);
// orientation: a cubic SO(3) spline whose control rotations turn with a random, rate-limited
// yaw/pitch/roll process, steered so the camera always looks at a surface 1-6 m away. The
// flight starts at rest (for IMU initialisation) and ramps up.
#pragma once

#include <cstdint>
#include <string>

#include "core/geometry/se3.h"
#include "sim/motion_trajectory.h"
#include "sim/scene.h"

namespace pkslam::sim {

enum class MotionLevel { kEasy, kMedium, kDifficult };
MotionLevel ParseMotionLevel(const std::string& name);  // easy|medium|difficult; OptionError
std::string MotionLevelName(MotionLevel level);

struct MotionOptions {
  MotionLevel level = MotionLevel::kMedium;
  double duration_s = 60.0;       // flight length (after which the spline ends)
  double rest_s = 2.0;            // at rest at the start
  double clearance_m = 0.6;       // keep control points this far from objects
  double wall_clearance_m = 1.0;  // and from walls/floor/ceiling
  double min_height_m = 0.6;      // above the floor
  double max_height_m = 2.6;      // above the floor (capped by the ceiling)
  double min_view_m = 1.0;        // distance along the optical axis to the viewed surface
  double max_view_m = 6.0;

  void Check() const;
};

// Nominal speed (m/s), angular rate (deg/s) and knot spacing (s) of a level.
struct MotionLevelParams {
  double speed_mps;
  double angular_rate_dps;
  double knot_s;
};
MotionLevelParams ParamsFor(MotionLevel level);

// body_from_camera: the camera that should look at surfaces (cam0). Throws Error when the
// scene has no room or no free space for the requested clearance.
SplineTrajectory GenerateMotion(const Scene& scene, const MotionOptions& options,
                                const SE3d& body_from_camera, std::uint64_t seed,
                                std::int64_t t0_ns);

}  // namespace pkslam::sim
