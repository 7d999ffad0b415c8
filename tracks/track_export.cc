#include "tracks/track_export.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>

#include "core/util/error.h"
#include "core/util/output_file.h"
#include "io/euroc_sensor.h"
#include "io/sparse_model.h"
#include "io/text_rows.h"

namespace pkslam {

namespace fs = std::filesystem;

void SimulatedTracksExportOptions::Check() const {
  PKSLAM_CHECK_OPTION(noise_px >= 0, "noise", "{}", noise_px);
  PKSLAM_CHECK_OPTION(every >= 1, "every", "{}", every);
  PKSLAM_CHECK_OPTION(start_s >= 0 && duration_s >= 0, "window", "start {} duration {}", start_s,
                      duration_s);
}

namespace {

fs::path Require(const fs::path& file, const std::string& hint) {
  if (!fs::exists(file)) throw InputError(file, "not found (" + hint + ")");
  return file;
}

// cam0's world_from_camera at t_ns: the exact simulator poses when the sequence has them,
// else the dataset's ground truth (nearest pose within 5 ms) times cam0's T_BS.
class CameraTruth {
 public:
  explicit CameraTruth(const fs::path& dataset) {
    const fs::path exact = dataset / "truth" / "tracks_trajectory.txt";
    if (fs::exists(exact)) {
      poses_ = ReadTrajectory(exact, TrajectoryFormat::kTum);
      return;
    }
    poses_ = ReadTrajectory(
        Require(dataset / "mav0" / "state_groundtruth_estimate0" / "data.csv", "ground truth"));
    body_from_camera_ =
        ReadEurocCameraSensor(Require(dataset / "mav0" / "cam0" / "sensor.yaml", "cam0"))
            .body_from_camera;
  }

  std::optional<SE3d> At(std::int64_t t_ns) const {
    const auto& p = poses_.poses;
    const auto it = std::lower_bound(
        p.begin(), p.end(), t_ns, [](const StampedPose& s, std::int64_t t) { return s.t_ns < t; });
    const StampedPose* best = nullptr;
    for (auto c : {it, it == p.begin() ? it : std::prev(it)}) {
      if (c == p.end()) continue;
      if (!best || std::llabs(c->t_ns - t_ns) < std::llabs(best->t_ns - t_ns)) best = &*c;
    }
    if (!best || std::llabs(best->t_ns - t_ns) > 5'000'000) return std::nullopt;
    return best->pose * body_from_camera_;
  }

 private:
  Trajectory poses_;
  SE3d body_from_camera_;
};

}  // namespace

ExportedTracks ExportSimulatedTracks(const fs::path& sequence,
                                     const SimulatedTracksExportOptions& options) {
  options.Check();
  const std::string hint = "simulate the sequence with --tracks N";
  const TrackSet exact = ReadTrackFile(Require(sequence / "truth" / "tracks_exact.txt", hint));
  const Trajectory trajectory = ReadTrajectory(
      Require(sequence / "truth" / "tracks_trajectory.txt", hint), TrajectoryFormat::kTum);
  ExportedTracks out;
  out.tracks.camera = exact.camera;
  out.tracks.width = exact.width;
  out.tracks.height = exact.height;
  out.truth_points = ReadTrackPoints(Require(sequence / "truth" / "tracks_points.txt", hint));
  if (exact.observations.empty()) throw InputError(sequence / "truth/tracks_exact.txt", "empty");
  const double t0 = exact.observations.front().t_s;
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> noise(0.0, options.noise_px > 0 ? options.noise_px : 1.0);
  std::map<int, int> renumbered;  // source frame -> exported frame
  for (const TrackObservation& o : exact.observations) {
    const double t = o.t_s - t0;
    if (t < options.start_s - 1e-9) continue;
    if (options.duration_s > 0 && t > options.start_s + options.duration_s + 1e-9) break;
    if (o.frame % options.every != 0) continue;
    auto [it, inserted] = renumbered.try_emplace(o.frame, static_cast<int>(renumbered.size()));
    TrackObservation e = o;
    e.frame = it->second;
    if (options.noise_px > 0) {
      e.u += noise(rng);
      e.v += noise(rng);
    }
    out.tracks.observations.push_back(e);
  }
  for (const auto& [source, frame] : renumbered) {
    if (source >= static_cast<int>(trajectory.poses.size())) {
      throw InputError(sequence / "truth/tracks_trajectory.txt",
                       fmt::format("no pose for frame {}", source));
    }
    out.truth.poses.push_back(trajectory.poses[static_cast<std::size_t>(source)]);
  }
  return out;
}

ExportedTracks ExportRunTracks(const fs::path& run, const fs::path& dataset, bool every_frame) {
  if (every_frame) {
    ExportedTracks out;
    out.tracks = ReadTrackFile(Require(run / "frame_tracks.txt", "run with --frame-tracks"));
    if (!dataset.empty()) {
      const CameraTruth truth(dataset);
      int last = -1;
      for (const TrackObservation& o : out.tracks.observations) {
        if (o.frame == last) continue;
        last = o.frame;
        const std::int64_t t_ns = std::llround(o.t_s * 1e9);
        if (const std::optional<SE3d> pose = truth.At(t_ns))
          out.truth.poses.push_back({t_ns, *pose});
      }
    }
    return out;
  }
  const SparseModel model = ReadSparseModel(Require(run / "sparse_model.txt", "a pkslam run"));
  ExportedTracks out;
  out.tracks.camera = {model.camera.fx, model.camera.fy, model.camera.cx, model.camera.cy, 0};
  out.tracks.width = model.camera.width;
  out.tracks.height = model.camera.height;
  std::vector<const SparseKeyframe*> keyframes;
  for (const SparseKeyframe& k : model.keyframes) keyframes.push_back(&k);
  std::sort(keyframes.begin(), keyframes.end(),
            [](const SparseKeyframe* a, const SparseKeyframe* b) { return a->t_ns < b->t_ns; });
  std::optional<CameraTruth> truth;
  if (!dataset.empty()) truth.emplace(dataset);
  int frame = 0;
  for (const SparseKeyframe* k : keyframes) {
    std::vector<std::pair<std::int64_t, const SparseKeypoint*>> observed;
    for (const SparseKeypoint& kp : k->keypoints) {
      if (kp.point_id >= 0) observed.emplace_back(kp.point_id, &kp);
    }
    // One observation per track and frame (a map point is matched to one keypoint).
    std::sort(observed.begin(), observed.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    observed.erase(std::unique(observed.begin(), observed.end(),
                               [](const auto& a, const auto& b) { return a.first == b.first; }),
                   observed.end());
    for (const auto& [id, kp] : observed) {
      if (id > std::numeric_limits<int>::max()) {
        throw InputError(run / "sparse_model.txt", fmt::format("point id {} too large", id));
      }
      out.tracks.observations.push_back(
          {frame, static_cast<double>(k->t_ns) * 1e-9, static_cast<int>(id), kp->u, kp->v});
    }
    if (truth) {
      const std::optional<SE3d> pose = truth->At(k->t_ns);
      if (pose) out.truth.poses.push_back({k->t_ns, *pose});
    }
    ++frame;
  }
  return out;
}

void WriteExportedTracks(const ExportedTracks& exported, const fs::path& out) {
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw OutputError(out, "cannot create: " + ec.message());
  WriteTrackFile(exported.tracks, out / "tracks.txt");
  if (!exported.truth.poses.empty())
    WriteTrajectoryTum(exported.truth, out / "truth_trajectory.txt");
  if (!exported.truth_points.empty())
    WriteTrackPoints(exported.truth_points, out / "truth_points.txt");
}

}  // namespace pkslam
