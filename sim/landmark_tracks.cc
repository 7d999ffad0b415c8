#include "sim/landmark_tracks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "core/util/output_file.h"
#include "sim/random.h"

namespace pkslam::sim {

void LandmarkTracksOptions::Check() const {
  PKSLAM_CHECK_OPTION(count > 0, "tracks", "{} landmarks", count);
  PKSLAM_CHECK_OPTION(max_depth_m > 0, "tracks depth", "{}", max_depth_m);
}

LandmarkTracks::LandmarkTracks(const Scene& scene, const CameraModel& camera,
                               const LandmarkTracksOptions& options)
    : scene_(scene), camera_(camera), options_(options) {
  options_.Check();
  // Faces by area (cylinder caps by their square's area: samples outside the disc are drawn
  // again).
  struct FaceRef {
    int shape, face;
    Eigen::Vector2f size;
  };
  std::vector<FaceRef> faces;
  std::vector<double> cumulative;
  double total = 0;
  for (int s = 0; s < static_cast<int>(scene.shapes.size()); ++s) {
    for (int f = 0; f < scene.shapes[static_cast<std::size_t>(s)].num_faces(); ++f) {
      const Scene::FaceFrame frame = Scene::Face(scene.shapes[static_cast<std::size_t>(s)], f);
      total += static_cast<double>(frame.size.x()) * frame.size.y();
      faces.push_back({s, f, frame.size});
      cumulative.push_back(total);
    }
  }
  PKSLAM_CHECK(total > 0, "the scene has no surface");
  Rng rng(DeriveSeed(options_.seed, 0x4C414E44));
  while (static_cast<int>(landmarks_.size()) < options_.count) {
    const double pick = rng.Uniform() * total;
    const std::size_t i = static_cast<std::size_t>(
        std::upper_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin());
    const FaceRef& face = faces[std::min(i, faces.size() - 1)];
    const Eigen::Vector2f uv(static_cast<float>(rng.Uniform()) * face.size.x(),
                             static_cast<float>(rng.Uniform()) * face.size.y());
    Eigen::Vector3f p, n;
    if (!Scene::SurfacePoint(scene.shapes[static_cast<std::size_t>(face.shape)], face.face, uv, &p,
                             &n)) {
      continue;
    }
    landmarks_.push_back(p.cast<double>());
    normals_.push_back(n.cast<double>());
  }
  tracks_.camera = {camera.fx(), camera.fy(), camera.cx(), camera.cy(), 0};
  tracks_.width = camera.width();
  tracks_.height = camera.height();
}

void LandmarkTracks::AddFrame(int frame, std::int64_t t_ns, const SE3d& world_from_camera) {
  PKSLAM_CHECK(trajectory_.poses.empty() || (frame == static_cast<int>(trajectory_.poses.size()) &&
                                             t_ns > trajectory_.poses.back().t_ns),
               "landmark tracks: frames must be consecutive and in time order");
  trajectory_.poses.push_back({t_ns, world_from_camera});
  const SE3d camera_from_world = world_from_camera.Inverse();
  const Eigen::Vector3d& centre = world_from_camera.translation();
  const Eigen::Vector3f origin = centre.cast<float>();
  for (std::size_t i = 0; i < landmarks_.size(); ++i) {
    const Eigen::Vector3d& p = landmarks_[i];
    const Eigen::Vector3d c = camera_from_world * p;
    if (c.z() <= 0.05 || c.z() > options_.max_depth_m) continue;
    if (normals_[i].dot(centre - p) <= 0) continue;  // the back of the surface
    const std::optional<Eigen::Vector2d> distorted = camera_.Project(c);
    if (!distorted || !camera_.InImage(*distorted)) continue;
    // Occluded when anything lies on the ray before the landmark (1 mm short of it).
    const Eigen::Vector3d ray = p - centre;
    const double distance = ray.norm();
    Hit hit;
    if (scene_.Intersect(origin, (ray / distance).cast<float>(),
                         static_cast<float>(distance - 1e-3), &hit)) {
      continue;
    }
    tracks_.observations.push_back({frame, static_cast<double>(t_ns) * 1e-9, static_cast<int>(i),
                                    camera_.fx() * c.x() / c.z() + camera_.cx(),
                                    camera_.fy() * c.y() / c.z() + camera_.cy()});
  }
}

void LandmarkTracks::Write(const std::filesystem::path& dir) const {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw OutputError(dir, "cannot create: " + ec.message());
  WriteTrackFile(tracks_, dir / "tracks_exact.txt");
  WriteTrajectoryTum(trajectory_, dir / "tracks_trajectory.txt");
  TrackPoints points;
  for (std::size_t i = 0; i < landmarks_.size(); ++i) {
    points.emplace_back(static_cast<int>(i), landmarks_[i]);
  }
  WriteTrackPoints(points, dir / "tracks_points.txt", "track x y z (world, metres)");
}

}  // namespace pkslam::sim
