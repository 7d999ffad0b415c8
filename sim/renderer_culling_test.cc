// Tile culling by part spheres (SegmentSpheres) may only drop shapes no ray of a tile can hit:
// the spheres must cover each shape, and a rendered depth image must be the one a test of every
// ray against every shape gives.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/renderer.h"
#include "sim/sim_testing.h"

namespace pkslam::sim {
namespace {

bool Covered(const std::vector<BoundSphere>& spheres, const Eigen::Vector3f& p_local) {
  for (const BoundSphere& s : spheres) {
    if ((p_local - s.centre_local).norm() <= s.radius * (1.0f + 1e-5f)) return true;
  }
  return false;
}

Shape MakeShape(ShapeType type, const Eigen::Vector3f& half) {
  Shape s;
  s.type = type;
  s.half = half;
  return s;
}

TEST(SegmentSpheres, CoverEveryPointOfLongFlatAndCompactShapes) {
  const std::vector<Shape> shapes = {
      MakeShape(ShapeType::kBox, {0.3f, 0.3f, 0.3f}),       // compact: its own bound
      MakeShape(ShapeType::kBox, {4.0f, 0.05f, 0.05f}),     // a rail
      MakeShape(ShapeType::kBox, {2.0f, 1.5f, 0.1f}),       // a slab
      MakeShape(ShapeType::kQuad, {1.0f, 0.7f, 0.0f}),      // a mat
      MakeShape(ShapeType::kCylinder, {0.1f, 0.1f, 3.0f}),  // a pipe
      MakeShape(ShapeType::kCylinder, {1.0f, 1.0f, 0.1f}),  // a disc
  };
  for (const Shape& shape : shapes) {
    const std::vector<BoundSphere> spheres = SegmentSpheres(shape);
    ASSERT_GE(spheres.size(), 1u);
    EXPECT_LE(spheres.size(), 16u);
    // Points over the shape's bounding box (a cylinder's box holds the cylinder), corners
    // and faces included.
    const int n = 24;
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j) {
        for (int k = 0; k <= n; ++k) {
          Eigen::Vector3f p = shape.half.cwiseProduct(
              Eigen::Vector3f(2.0f * i / n - 1.0f, 2.0f * j / n - 1.0f, 2.0f * k / n - 1.0f));
          if (shape.type == ShapeType::kCylinder &&
              std::hypot(p.x(), p.y()) > shape.half.x() * (1.0f + 1e-5f)) {
            continue;
          }
          ASSERT_TRUE(Covered(spheres, p))
              << "shape half " << shape.half.transpose() << ", point " << p.transpose();
        }
      }
    }
  }
  // Long and flat shapes are split, so each part is much smaller than the whole.
  EXPECT_GT(SegmentSpheres(shapes[1]).size(), 1u);
  EXPECT_LT(SegmentSpheres(shapes[1])[0].radius, 0.5f * shapes[1].bound_radius());
  EXPECT_GT(SegmentSpheres(shapes[4]).size(), 1u);
  EXPECT_EQ(SegmentSpheres(shapes[0]).size(), 1u);
  EXPECT_TRUE(SegmentSpheres(MakeShape(ShapeType::kRoom, {5.0f, 5.0f, 3.0f})).empty());
}

// Every pixel's depth against the nearest hit of its ray over all shapes (Scene::Intersect, no
// culling), along a flight through the EuRoC machine hall (pipes, rails, machines).
TEST(RendererCulling, DepthEqualsTheNearestHitOverEveryShape) {
  SceneBuildOptions build;
  build.texture_size = 64;
  const Scene scene = BuildScene(LoadSceneDescription("euroc_machine_hall"), build, {});
  const CameraRig cam = EurocCam0();
  const SplineTrajectory flight = RandomTestFlight(scene, MotionLevel::kMedium, 20, 3);
  // A quarter-resolution EuRoC camera keeps the brute-force test short.
  const CameraRays rays(CameraModel::Pinhole(188, 120, 114.0, 114.0, 93.5, 59.5));
  RenderOptions options;
  options.depth = true;
  const Renderer renderer(scene, options);
  int pixels = 0;
  int mismatches = 0;
  for (int k = 0; k < 6; ++k) {
    const SE3d world_from_camera =
        flight.WorldFromBody(3'000'000'000LL * (k + 1)) * cam.body_from_camera;
    RenderBuffers out;
    renderer.Render(rays, world_from_camera, &out);
    const Eigen::Matrix3f r_wc = world_from_camera.RotationMatrix().cast<float>();
    const Eigen::Vector3f o_w = world_from_camera.translation().cast<float>();
    for (int y = 0; y < rays.height(); ++y) {
      for (int x = 0; x < rays.width(); ++x) {
        const Eigen::Vector3f& rc = rays.Ray(x, y);
        Hit hit;
        const bool found = scene.Intersect(o_w, r_wc * rc, options.max_distance, &hit);
        const float expected = found ? hit.t * rc.z() : 0.0f;
        ++pixels;
        // The two compute each shape's local ray in a different order (float rounding).
        if (std::abs(out.depth.at<float>(y, x) - expected) > 1e-3f * (1.0f + expected)) {
          ++mismatches;
        }
      }
    }
  }
  EXPECT_EQ(mismatches, 0) << "of " << pixels << " pixels";
}

}  // namespace
}  // namespace pkslam::sim
