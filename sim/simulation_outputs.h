// The output side of `pkslam simulate` (simulator.cc's RunSimulation): the settings file, the
// IMU and ground-truth rows, the reference clouds, the motion's statistics, and clearing an
// earlier render. Internal to sim/.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "sim/body_motion.h"
#include "sim/euroc_writer.h"
#include "sim/reference_cloud.h"
#include "sim/simulator.h"

namespace pkslam::sim {

// Seconds as nanoseconds, rounded.
std::int64_t Ns(double s);

// ORB-SLAM3-format settings of the simulated rig (io/settings.h writes the file).
void WriteSettings(const std::filesystem::path& file, const std::vector<CameraRig>& cameras,
                   const SimulationOptions& o);

// Path length, mean speed and angular rates of the flight, sampled every `step`.
void MotionStatistics(const SplineTrajectory& traj, std::int64_t begin, std::int64_t end,
                      std::int64_t step, SimulationSummary* s);

// IMU samples, and the ground truth as evaluation will see it (realism: the state at the stamp
// plus the ground-truth time offset, with motion-capture noise) and exactly (truth/).
void WriteImuAndGroundTruth(const BodyMotion& motion, const std::vector<ImuSample>& imu,
                            const SimulationOptions& o, EurocWriter* euroc);

// reference_cloud.ply (and reference_observed.ply with an observed range).
void WriteReferenceClouds(const Scene& scene, const SurfaceVisibility* visibility,
                          const SurfaceVisibility* observed, const SimulationOptions& o,
                          SimulationSummary* summary);

// A render goes into an empty folder or replaces an earlier render (sim.yaml) there, entry by
// entry, so a --no-images render never leaves older images beside new IMU and ground truth. Any
// other folder is left alone: `--out` onto a recording would mix the two (docs/robustness.md).
void ClearEarlierRender(const std::filesystem::path& dir);

}  // namespace pkslam::sim
