// Helpers shared by the sim/ tests.
#pragma once

#include <cstdint>

#include "sim/euroc_writer.h"
#include "sim/motion_generator.h"
#include "sim/scene_builder.h"
#include "sim/scene_description.h"

namespace pkslam::sim {

// A random flight of `level` through `scene`, the camera mounted like EuRoC's cam0, starting
// at t = 0.
inline SplineTrajectory RandomTestFlight(const Scene& scene, MotionLevel level, double seconds,
                                         std::uint64_t seed) {
  MotionOptions motion;
  motion.level = level;
  motion.duration_s = seconds;
  return GenerateMotion(scene, motion, EurocCam0().body_from_camera, seed, 0);
}

// The same through the Vicon room (tiny textures: the motion planner needs only the geometry).
inline SplineTrajectory RandomTestFlight(MotionLevel level, double seconds, std::uint64_t seed) {
  SceneBuildOptions build;
  build.texture_size = 16;
  return RandomTestFlight(BuildScene(LoadSceneDescription("vicon_room"), build, {}), level, seconds,
                          seed);
}

}  // namespace pkslam::sim
