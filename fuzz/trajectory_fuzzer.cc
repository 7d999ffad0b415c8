// Fuzz target: trajectory files (io/trajectory.h). The input is the file, read with format
// detection and with each explicit format (tum, euroc, orbslam3). Bad input must end in
// InputError (file and line); anything else is a finding. A trajectory that was read must also
// be made of rigid transforms and survive what callers do next: its measures, and a write/read
// round trip in the same format that gives back the same timestamps exactly (the header
// promises it).
#include <fmt/format.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/util/error.h"
#include "fuzz/fuzz_support.h"
#include "io/trajectory.h"

namespace {

using namespace pkslam;

void RoundTrip(const Trajectory& trajectory, TrajectoryFormat format) {
  const auto file = fuzz::ScratchDir() / "written.txt";
  WriteTrajectory(trajectory, file, format);
  Trajectory back;
  try {
    back = ReadTrajectory(file, format, DuplicateTimestamps::kError);
  } catch (const InputError& e) {
    fuzz::Finding(fmt::format("a written {} trajectory does not read back: {}",
                              TrajectoryFormatName(format), e.what()));
  }
  if (back.Timestamps() != trajectory.Timestamps()) {
    fuzz::Finding(
        fmt::format("{} round trip changed the timestamps", TrajectoryFormatName(format)));
  }
  if (format == TrajectoryFormat::kEuroc && back.has_extras() != trajectory.has_extras()) {
    fuzz::Finding("euroc round trip lost or invented the 17-column extras");
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  pkslam::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = fuzz::WriteScratchFile("trajectory.txt", data, size);
  try {
    DetectTrajectoryFormat(file);
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }
  try {
    ReadTrajectory(file, TrajectoryFormat::kAuto, DuplicateTimestamps::kError);
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }
  for (const TrajectoryFormat format : {TrajectoryFormat::kAuto, TrajectoryFormat::kTum,
                                        TrajectoryFormat::kEuroc, TrajectoryFormat::kOrbSlam3}) {
    Trajectory trajectory;
    try {
      trajectory = ReadTrajectory(file, format);
    } catch (const InputError& e) {
      fuzz::Rejected(e);
      continue;
    }
    for (const StampedPose& p : trajectory.poses) {
      if (!p.pose.translation().allFinite() ||
          !(std::abs(p.pose.quaternion().norm() - 1.0) < 1e-6)) {
        fuzz::Finding("a trajectory was read with a pose that is not a rigid transform");
      }
    }
    PathLengthMeters(trajectory);
    DurationSeconds(trajectory);
    if (format != TrajectoryFormat::kAuto) RoundTrip(trajectory, format);
  }
  return 0;
}
