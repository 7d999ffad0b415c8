#include "evaluation/bench/peer_import.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "core/util/error.h"
#include "core/util/json_writer.h"
#include "io/euroc_dataset.h"
#include "io/rigid_transform_file.h"
#include "io/trajectory.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

bool Inertial(const std::string& sensor) { return sensor.find("inertial") != std::string::npos; }

// wall_s=... from summary.txt (NaN when absent).
double WallSeconds(const fs::path& summary) {
  std::ifstream in(summary);
  std::string word;
  while (in >> word) {
    if (word.rfind("wall_s=", 0) == 0) {
      try {
        return std::stod(word.substr(7));
      } catch (const std::exception&) {
        return std::numeric_limits<double>::quiet_NaN();
      }
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// Median of the second column of track_times.txt, in ms (NaN when absent).
double MedianTrackingMs(const fs::path& file) {
  std::ifstream in(file);
  std::vector<double> ms;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    double t = 0.0;
    double seconds = 0.0;
    if (row >> t >> seconds) ms.push_back(1e3 * seconds);
  }
  if (ms.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(ms.begin(), ms.begin() + static_cast<std::ptrdiff_t>(ms.size() / 2), ms.end());
  return ms[ms.size() / 2];
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
  json.Member("map_points", 0);
  json.Member("wall_time_s", WallSeconds(run_dir / "summary.txt"));
  json.Member("median_tracking_ms", MedianTrackingMs(run_dir / "track_times.txt"));
  json.EndObject();
  const fs::path stats = run_dir / "stats.json";
  std::ofstream out(stats, std::ios::trunc);
  out << json.str();
  if (!out) throw Error("cannot write " + stats.string());
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
