#include "dense/visibility.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/util/error.h"

namespace pkslam::dense {
namespace {

// A camera at the origin looking along +z (camera = world).
CameraModel VisibilityCamera() { return CameraModel::Pinhole(640, 480, 400, 400, 319.5, 239.5); }

// A wall at z = 3 (x, y in [-1, 1]) and a 0.4 m square board at z = 2 in front of its centre,
// both sampled every 1 cm.
struct Scene {
  std::vector<Eigen::Vector3f> points;
  std::vector<int> kind;  // 0 wall, 1 board
};

Scene MakeScene() {
  Scene s;
  for (int i = -100; i <= 100; ++i) {
    for (int j = -100; j <= 100; ++j) {
      s.points.emplace_back(0.01f * i, 0.01f * j, 3.0f);
      s.kind.push_back(0);
    }
  }
  for (int i = -20; i <= 20; ++i) {
    for (int j = -20; j <= 20; ++j) {
      s.points.emplace_back(0.01f * i, 0.01f * j, 2.0f);
      s.kind.push_back(1);
    }
  }
  return s;
}

TEST(VisibilityTest, BoardOccludesTheWallBehindIt) {
  const Scene s = MakeScene();
  VisibilityOptions o;
  const auto visible = VisibleFromCameras(s.points, {SE3d()}, VisibilityCamera(), o);
  int board_visible = 0, board = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    if (s.kind[i] == 1) {
      ++board;
      board_visible += visible[i];
    }
  }
  EXPECT_EQ(board_visible, board);
  // Behind the board's centre: hidden (the board at 2 m spans |x| < 0.3 m on the wall).
  auto index_of_wall = [](int i, int j) {
    return static_cast<std::size_t>((i + 100) * 201 + j + 100);
  };
  EXPECT_EQ(visible[index_of_wall(0, 0)], 0);
  EXPECT_EQ(visible[index_of_wall(25, 0)], 0);
  // Outside its shadow (and inside the image): visible.
  EXPECT_EQ(visible[index_of_wall(60, 0)], 1);
  EXPECT_EQ(visible[index_of_wall(-60, 50)], 1);
  // From 1.5 m in front of the wall (camera_from_world: z' = z - 1.5) the wall's corner
  // projects below the image (v = 400 / 1.5 + 239.5 = 506 > 480); (0, 0.8) is inside the
  // image and outside the board's shadow (0.6 m).
  const SE3d closer(SO3d(), Eigen::Vector3d(0, 0, -1.5));
  const auto near = VisibleFromCameras(s.points, {closer}, VisibilityCamera(), o);
  EXPECT_EQ(near[index_of_wall(100, 100)], 0);
  EXPECT_EQ(near[index_of_wall(0, 80)], 1);
}

TEST(VisibilityTest, DepthRangeAndUnionOverCameras) {
  const Scene s = MakeScene();
  VisibilityOptions o;
  o.max_depth_m = 2.5;  // the wall is beyond it
  const auto visible = VisibleFromCameras(s.points, {SE3d()}, VisibilityCamera(), o);
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    ASSERT_EQ(visible[i], s.kind[i] == 1 ? 1 : 0) << i;
  }
  // A second camera looking at the wall from behind it (rotated 180 degrees about y, placed at
  // z = 5) sees the wall's back, including the part the board hides from the first.
  const SE3d world_from_back(SO3d::Exp(Eigen::Vector3d(0, M_PI, 0)), Eigen::Vector3d(0, 0, 5));
  const auto both = VisibleFromCameras(s.points, {SE3d(), world_from_back.Inverse()}, VisibilityCamera(),
                                       VisibilityOptions{});
  EXPECT_EQ(both[static_cast<std::size_t>(100 * 201 + 100)], 1);  // wall centre
  EXPECT_EQ(both[s.points.size() - 1], 1);                        // a board corner
  VisibilityOptions bad;
  bad.max_depth_m = 0.1;
  EXPECT_THROW(bad.Check(), OptionError);
}

}  // namespace
}  // namespace pkslam::dense
