// Landmark tracks see what the camera sees: exact pinhole projections, nothing behind an
// object or behind a surface, nothing outside the image; reproducible from the seed.
#include "sim/landmark_tracks.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/util/error.h"

namespace pkslam::sim {
namespace {

// A 10 x 10 x 4 m room with a 1 m cube 1.5-2.5 m in front of a camera at the centre that
// looks along +x.
Scene RoomWithCube() {
  Scene scene;
  Shape room;
  room.type = ShapeType::kRoom;
  room.half = {5, 5, 2};
  scene.shapes.push_back(room);
  Shape cube;
  cube.type = ShapeType::kBox;
  cube.center = {2, 0, 0};
  cube.half = {0.5f, 0.5f, 0.5f};
  scene.shapes.push_back(cube);
  return scene;
}

SE3d LookAlongX() {
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(0, -1, 0);  // camera x (right) = world -y
  r.col(1) = Eigen::Vector3d(0, 0, -1);  // camera y (down) = world -z
  r.col(2) = Eigen::Vector3d(1, 0, 0);   // camera z (forward) = world x
  return SE3d(SO3d(r), Eigen::Vector3d::Zero());
}

TEST(LandmarkTracks, ProjectsWhatTheCameraSeesAndNothingElse) {
  const Scene scene = RoomWithCube();
  const CameraModel camera = CameraModel::Pinhole(752, 480, 460, 460, 376, 240);
  LandmarkTracks tracks(scene, camera, {4000, 8.0, 3});
  tracks.AddFrame(0, 1'000'000'000, LookAlongX());
  const SE3d camera_from_world = LookAlongX().Inverse();
  int on_cube = 0;
  ASSERT_GT(tracks.tracks().observations.size(), 100u);
  for (const TrackObservation& o : tracks.tracks().observations) {
    const Eigen::Vector3d& p = tracks.landmarks()[static_cast<std::size_t>(o.track)];
    const Eigen::Vector3d c = camera_from_world * p;
    EXPECT_NEAR(o.u, 460 * c.x() / c.z() + 376, 1e-6);
    EXPECT_NEAR(o.v, 460 * c.y() / c.z() + 240, 1e-6);
    EXPECT_TRUE(o.u >= -0.5 && o.u < 751.5 && o.v >= -0.5 && o.v < 479.5);
    EXPECT_GT(p.x(), 0) << "behind the camera";
    // Only the cube's front face (x = 1.5) of the cube is visible from here.
    const bool cube_point = std::abs(p.y()) <= 0.5001 && std::abs(p.z()) <= 0.5001 &&
                            p.x() >= 1.4999 && p.x() <= 2.5001;
    if (cube_point) {
      EXPECT_NEAR(p.x(), 1.5, 1e-4);
      ++on_cube;
      continue;
    }
    // A wall point whose ray passes through the cube is hidden.
    const double s = 1.5 / p.x();
    EXPECT_FALSE(std::abs(s * p.y()) < 0.49 && std::abs(s * p.z()) < 0.49)
        << "occluded point seen: " << p.transpose();
  }
  EXPECT_GT(on_cube, 0);
  EXPECT_EQ(tracks.tracks().observations.front().t_s, 1.0);

  LandmarkTracks again(scene, camera, {4000, 8.0, 3});
  again.AddFrame(0, 1'000'000'000, LookAlongX());
  ASSERT_EQ(again.tracks().observations.size(), tracks.tracks().observations.size());
  EXPECT_EQ(again.landmarks(), tracks.landmarks());
  EXPECT_THROW(again.AddFrame(0, 2'000'000'000, LookAlongX()), Error);
}

}  // namespace
}  // namespace pkslam::sim
