// Reading recorded trajectories for replay: TUM text (`t[s] x y z qx qy qz qw`) and EuRoC
// csv (`t[ns],x,y,z,qw,qx,qy,qz[,...]`). Timestamps are parsed exactly from their decimal
// text into int64 ns (a double cannot hold 1.4e9 s to the nanosecond).
// Private to sim/ until io/trajectory.h lands on main.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

#include "sim/trajectory.h"

namespace pkslam::sim {

// Throws InputError (file:line) on malformed lines, non-increasing timestamps, bad
// quaternions, or fewer than two poses.
std::vector<PoseSample> ReadPoseFile(const std::filesystem::path& path);

// "1403715524.90714" -> 1403715524907140000; "1403715273262142976" (no point) -> as is when
// `integer_is_ns`, else seconds. nullopt-like failure reported by returning false.
bool ParseTimestampNs(std::string_view text, bool integer_is_ns, std::int64_t* t_ns);

}  // namespace pkslam::sim
