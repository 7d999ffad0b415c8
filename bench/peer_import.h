// A peer SLAM system's run folder turned into the files of a `pkslam run` folder, so the bench
// evaluates the peer and pkslam alike (same association, alignment and coverage). The peer's
// output contract is that of ../shared/tools/peer/run_orbslam3.sh (ORB-SLAM3 v1.0's EuRoC
// examples):
//   traj_tum.txt     every tracked frame, TUM (t[s] x y z qx qy qz qw): the body (IMU) frame
//                    for inertial sensors, cam0 otherwise; lost frames are absent
//   kf_tum.txt       the keyframes, same frame and format (optional)
//   track_times.txt  "t_frame_s tracking_s" per frame (optional)
//   summary.txt      key=value words, wall_s=... peak_rss_mb=... (optional)
//   keyframes_created.txt  the number of keyframes it created, culled ones too (optional)
//   peer_build.txt   one line naming the peer's build (optional; results.csv's peer_build)
//   time.txt         /usr/bin/time -v of the peer process: user and system time (optional)
// What is written: trajectory_body.txt (inertial sensors) or trajectory.txt plus
// body_from_camera.txt (visual sensors: cam0's T_BS from the dataset, the extrinsic the peer
// was given), keyframes.txt and a stats.json with frames = the dataset's cam0 frames,
// lost_frames = frames without a pose, keyframes, wall time, sequence duration (last - first
// cam0 timestamp, as `pkslam run` measures it), realtime factor (sequence / wall), median and
// 95th-percentile tracking time, process CPU time and peak memory; what the peer's files lack
// is null.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace pkslam::bench {

// Throws InputError when traj_tum.txt is missing, empty or malformed.
void ImportPeerRun(const std::filesystem::path& run_dir, const std::filesystem::path& dataset,
                   const std::string& sensor);

// The peer command with {dataset}, {sensor}, {out}, {seed} and {suite_dir} substituted.
std::vector<std::string> PeerArguments(const std::vector<std::string>& command,
                                       const std::filesystem::path& dataset,
                                       const std::string& sensor, const std::filesystem::path& out,
                                       std::uint64_t seed, const std::filesystem::path& suite_dir);

}  // namespace pkslam::bench
