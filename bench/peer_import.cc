#include "bench/peer_import.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/util/error.h"
#include "core/util/json_writer.h"
#include "core/util/output_file.h"
#include "core/util/quantile.h"
#include "io/euroc_dataset.h"
#include "io/rigid_transform_file.h"
#include "io/trajectory.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

bool Inertial(const std::string& sensor) { return sensor.find("inertial") != std::string::npos; }

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The number after "KEY" (e.g. "wall_s=") among the words of a file, NaN when absent or not a
// number (run_orbslam3.sh writes "wall_s=?" when it could not measure).
double NumberAfter(const fs::path& file, const std::string& key) {
  std::ifstream in(file);
  std::string word;
  while (in >> word) {
    if (word.rfind(key, 0) != 0) continue;
    try {
      return std::stod(word.substr(key.size()));
    } catch (const std::exception&) {
      return kNaN;
    }
  }
  return kNaN;
}

// Process CPU time from /usr/bin/time -v (time.txt): user + system seconds, NaN when absent.
double CpuSeconds(const fs::path& time_txt) {
  std::ifstream in(time_txt);
  double sum = 0.0;
  int found = 0;
  std::string line;
  for (const char* label : {"User time (seconds): ", "System time (seconds): "}) {
    in.clear();
    in.seekg(0);
    while (std::getline(in, line)) {
      const std::size_t at = line.find(label);
      if (at == std::string::npos) continue;
      try {
        sum += std::stod(line.substr(at + std::string(label).size()));
        ++found;
      } catch (const std::exception&) {
      }
      break;
    }
  }
  return found == 2 ? sum : kNaN;
}

// Per-frame tracking times (ms) from the second column of track_times.txt.
std::vector<double> TrackingMs(const fs::path& file) {
  std::ifstream in(file);
  std::vector<double> ms;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    double t = 0.0;
    double seconds = 0.0;
    if (row >> t >> seconds) ms.push_back(1e3 * seconds);
  }
  return ms;
}

// Last minus first cam0 timestamp: `pkslam run`'s sequence_duration_s for the same dataset.
double SequenceSeconds(const EurocDataset& data) {
  const auto& images = data.cam0().images;
  if (images.size() < 2) return kNaN;
  return 1e-9 * static_cast<double>(images.back().t_ns - images.front().t_ns);
}

std::string Replace(std::string text, const std::string& key, const std::string& value) {
  for (std::size_t at = text.find(key); at != std::string::npos;
       at = text.find(key, at + value.size())) {
    text.replace(at, key.size(), value);
  }
  return text;
}

}  // namespace

void ImportPeerRun(const fs::path& run_dir, const fs::path& dataset, const std::string& sensor) {
  const fs::path traj_file = run_dir / "traj_tum.txt";
  if (!fs::exists(traj_file) || fs::file_size(traj_file) == 0) {
    throw InputError(traj_file, "the peer wrote no trajectory (see peer.log in the run folder)");
  }
  const Trajectory trajectory = ReadTrajectory(traj_file, TrajectoryFormat::kTum);
  const EurocDataset data = EurocDataset::Open(dataset);
  const bool inertial = Inertial(sensor);
  WriteTrajectoryTum(trajectory, run_dir / (inertial ? "trajectory_body.txt" : "trajectory.txt"));
  if (!inertial) {
    WriteRigidTransform(data.cam0_sensor().body_from_camera, run_dir / "body_from_camera.txt",
                        "cam0 T_BS of the dataset (the extrinsic the peer read)");
    if (sensor.rfind("stereo", 0) == 0) {
      // A stereo map is metric: its body trajectory is right, and it is what the bench
      // compares stereo runs by (as pkslam's own trajectory_body.txt).
      Trajectory body = trajectory;
      const SE3d camera_from_body = data.cam0_sensor().body_from_camera.Inverse();
      for (auto& p : body.poses) p.pose = p.pose * camera_from_body;
      WriteTrajectoryTum(body, run_dir / "trajectory_body.txt");
    }
  }
  const fs::path kf_file = run_dir / "kf_tum.txt";
  Trajectory keyframes;
  if (fs::exists(kf_file) && fs::file_size(kf_file) > 0) {
    keyframes = ReadTrajectory(kf_file, TrajectoryFormat::kTum);
  }
  WriteTrajectoryTum(keyframes, run_dir / "keyframes.txt");

  const int frames = static_cast<int>(data.cam0().images.size());
  const int tracked = static_cast<int>(trajectory.poses.size());
  JsonWriter json;
  json.BeginObject();
  json.Member("system", "peer");
  json.Member("dataset", dataset.string());
  json.Member("sensor", sensor);
  json.Member("frames", frames);
  json.Member("frames_in_trajectory", tracked);
  json.Member("lost_frames", std::max(frames - tracked, 0));
  json.Member("keyframes", static_cast<int>(keyframes.poses.size()));
  // Keyframes the peer created (culled ones too), when its script wrote the count: the
  // selector's rate, which the final map's count hides behind culling.
  const double created = NumberAfter(run_dir / "keyframes_created.txt", "");
  if (std::isfinite(created)) json.Member("keyframes_created", static_cast<int>(created));
  json.Member("map_points", 0);
  // The peer's wall time (/usr/bin/time) includes loading ORB-SLAM3's text vocabulary
  // (seconds), which pkslam's (its frame loop) does not. Its example program, unpaced, does
  // nothing in its frame loop but read an image and call Track*(), which track_times.txt
  // times: the sum of those is its loop's time without image decoding, the realtime factor's
  // denominator (slightly favouring the peer: pkslam's loop time includes waiting for decoded
  // images).
  const double wall_s = NumberAfter(run_dir / "summary.txt", "wall_s=");
  const double sequence_s = SequenceSeconds(data);
  const std::vector<double> tracking_ms = TrackingMs(run_dir / "track_times.txt");
  double loop_s = 0;
  for (double ms : tracking_ms) loop_s += 1e-3 * ms;
  json.Member("wall_time_s", wall_s);
  json.Member("tracking_loop_s", loop_s);
  json.Member("sequence_duration_s", sequence_s);
  json.Member("realtime_factor", loop_s > 0 ? sequence_s / loop_s : kNaN);
  // As `pkslam run` computes its percentiles (core/util/quantile.h); NaN for none.
  json.Member("median_tracking_ms", Quantile(tracking_ms, 0.5).value_or(kNaN));
  json.Member("p95_tracking_ms", Quantile(tracking_ms, 0.95).value_or(kNaN));
  json.Member("process_cpu_s", CpuSeconds(run_dir / "time.txt"));
  // run_orbslam3.sh: peak_rss_mb = "Maximum resident set size (kbytes)" / 1024, i.e. MiB.
  json.Member("peak_memory_mib", NumberAfter(run_dir / "summary.txt", "peak_rss_mb="));
  json.EndObject();
  const fs::path stats = run_dir / "stats.json";
  WriteFileAtomically(stats, json.str());
}

std::vector<std::string> PeerArguments(const std::vector<std::string>& command,
                                       const fs::path& dataset, const std::string& sensor,
                                       const fs::path& out, std::uint64_t seed,
                                       const fs::path& suite_dir) {
  std::vector<std::string> argv;
  for (std::string word : command) {
    word = Replace(word, "{dataset}", dataset.string());
    word = Replace(word, "{sensor}", sensor);
    word = Replace(word, "{out}", out.string());
    word = Replace(word, "{seed}", std::to_string(seed));
    word = Replace(word, "{suite_dir}", suite_dir.string());
    argv.push_back(word);
  }
  return argv;
}

}  // namespace pkslam::bench
