#include "sim/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/util/error.h"
#include "sim/intersect.h"
#include "sim/scene_builder.h"
#include "sim/scene_description.h"

namespace pkslam::sim {
namespace {

constexpr const char* kSmallRoom = R"(
name: small
room: {size: [6, 6, 3], materials: {walls: w, floor: w, ceiling: w}}
materials:
  w: {texture: {kind: noise}, tile: 1.0}
objects:
  - {type: box, name: crate, position: [1.0, 0.0, 0.0], size: [0.5, 0.5, 0.5], material: w}
  - {type: cylinder, name: pole, position: [-2.0, -2.0, 0.0], radius: 0.2, height: 2.0, material: w}
  - {type: shelf, name: shelf, position: [0.0, 2.5, 0.0], size: [1.5, 0.4, 1.8], levels: 3, material: [w, w]}
)";

SceneBuildOptions Tiny() {
  SceneBuildOptions o;
  o.texture_size = 16;
  return o;
}

int CountNamed(const Scene& scene, const std::string& name) {
  int n = 0;
  for (const Shape& s : scene.shapes) n += s.name == name ? 1 : 0;
  return n;
}

TEST(SceneDescription, BuiltinsParseAndExtend) {
  for (const std::string& name : BuiltinSceneNames()) {
    const SceneDescription d = LoadSceneDescription(name);
    EXPECT_FALSE(d.materials.empty()) << name;
  }
  EXPECT_EQ(LoadSceneDescription("weak_texture").texture_mode, "weak");
  EXPECT_EQ(LoadSceneDescription("repetitive").texture_mode, "repetitive");
  EXPECT_EQ(LoadSceneDescription("weak_texture").objects.size(),
            LoadSceneDescription("vicon_room").objects.size());
}

TEST(SceneDescription, ErrorsNameTheLine) {
  const std::string bad =
      std::string(kSmallRoom) + "  - {type: box, position: [0, 0, 0], size: [1, 1], material: w}\n";
  try {
    ParseSceneYaml(bad, "bad.yaml");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 10u);
    EXPECT_NE(std::string(e.what()).find("size"), std::string::npos);
  }
  EXPECT_THROW(ParseSceneYaml("room: {size: [6, 6, 3]}\nmaterials: {}\n", "x.yaml"), InputError);
  EXPECT_THROW(ParseSceneYaml(std::string(kSmallRoom) + "  - {type: box, material: nope}\n", "y"),
               InputError);
  EXPECT_THROW(ParseSceneYaml("{unclosed", "z.yaml"), InputError);
  EXPECT_THROW(LoadSceneDescription("/nonexistent/scene.yaml"), InputError);
}

TEST(SceneBuilder, RoomGrowsAroundThePathAndNearbyObjectsGo) {
  const SceneDescription d = ParseSceneYaml(kSmallRoom, "small");
  SceneBuildReport nominal;
  const Scene a = BuildScene(d, Tiny(), {}, &nominal);
  EXPECT_EQ(nominal.objects_removed, 0);
  EXPECT_EQ(CountNamed(a, "crate"), 1);
  EXPECT_GT(CountNamed(a, "shelf"), 5);  // sides, back, boards, goods
  // A path through the crate (inside the room): the crate goes, the room stays.
  std::vector<Eigen::Vector3d> path;
  for (double x = -1.0; x <= 1.2; x += 0.05) path.emplace_back(x, 0.0, 0.3);
  SceneBuildReport report;
  const Scene b = BuildScene(d, Tiny(), path, &report);
  EXPECT_EQ(CountNamed(b, "crate"), 0);
  EXPECT_EQ(CountNamed(b, "pole"), 1);
  EXPECT_EQ(report.objects_removed, 1);
  EXPECT_EQ(report.room_max, nominal.room_max);
  for (const auto& p : path) EXPECT_GT(b.ObjectClearance(p.cast<float>()), 0.6f);
  // A path leaving the room: the room grows to hold it with the margins (objects scale in
  // x, y with the room, so the crate moves out of the way and is kept).
  const std::vector<Eigen::Vector3d> far = {{0.0, 0.0, 1.0}, {5.0, 0.0, 2.9}};
  const Scene c = BuildScene(d, Tiny(), far, &report);
  EXPECT_GE(report.room_max.x(), 5.0 + 1.0);  // wall margin
  EXPECT_GE(report.room_max.z(), 2.9 + 0.5);  // ceiling margin
  EXPECT_EQ(report.room_min.x(), nominal.room_min.x());
  for (const auto& p : far) EXPECT_GT(c.RoomClearance(p.cast<float>()), 0.29f);
}

TEST(SceneBuilder, PathScatterStaysAlongTheFlightHoweverLargeTheRoom) {
  const std::string yaml = std::string(kSmallRoom) +
                           "scatter:\n"
                           "  - {type: box, count: 20, size_min: [0.4, 0.4, 0.5], size_max: [0.6, "
                           "0.6, 1.0], materials: [w], region: path, distance: [1.5, 3.0]}\n";
  const SceneDescription d = ParseSceneYaml(yaml, "path.yaml");
  ASSERT_EQ(d.scatter.size(), 1u);
  EXPECT_EQ(d.scatter[0].region, ScatterRegion::kPath);
  // A 40 m flight along x and one excursion to y = 20: the room grows to about 42 x 24 m, and the
  // scattered boxes stay along the path instead of spreading over the whole room.
  std::vector<Eigen::Vector3d> path;
  for (double x = -20.0; x <= 20.0; x += 0.25) path.emplace_back(x, 0.0, 1.0);
  path.emplace_back(0.0, 20.0, 1.0);
  SceneBuildReport report;
  const Scene scene = BuildScene(d, Tiny(), path, &report);
  EXPECT_GT(report.room_max.y(), 20.0);
  int scattered = 0;
  for (const Shape& s : scene.shapes) {
    if (s.name.rfind("scatter", 0) != 0) continue;
    ++scattered;
    // The drawn distance from some path point plus half the box's smaller side: at most
    // 3.0 + 0.3 m from the nearest one (the clearance keeps them off the path itself).
    double nearest = 1e9;
    for (const auto& p : path) {
      nearest = std::min(nearest, (p.head<2>() - s.center.head<2>().cast<double>()).norm());
    }
    EXPECT_LE(nearest, 3.3 + 1e-4) << s.name;
  }
  EXPECT_GE(scattered, 15);
  for (const auto& p : path) EXPECT_GT(scene.ObjectClearance(p.cast<float>()), 0.6f);

  EXPECT_THROW(ParseSceneYaml(std::string(kSmallRoom) +
                                  "scatter:\n  - {type: box, count: 1, materials: [w], region: "
                                  "pth}\n",
                              "typo.yaml"),
               InputError);
  EXPECT_THROW(ParseSceneYaml(std::string(kSmallRoom) +
                                  "scatter:\n  - {type: box, count: 1, materials: [w], region: "
                                  "path, distance: [3, 2]}\n",
                              "range.yaml"),
               InputError);
}

TEST(Scene, IntersectionsAndDistancesAgree) {
  const Scene scene = BuildScene(ParseSceneYaml(kSmallRoom, "small"), Tiny(), {});
  // From the room centre towards +x: the crate's -x face at x = 0.75, 0.25 m up.
  Hit hit;
  ASSERT_TRUE(scene.Intersect({-1.0f, 0.0f, 0.25f}, {1.0f, 0.0f, 0.0f}, 100.0f, &hit));
  EXPECT_NEAR(hit.t, 1.75f, 1e-5f);
  EXPECT_EQ(scene.shapes[hit.shape].name, "crate");
  EXPECT_NEAR(hit.normal.x(), -1.0f, 1e-6f);
  // Straight up: the ceiling at z = 3.
  ASSERT_TRUE(scene.Intersect({-1.0f, 0.0f, 0.25f}, {0.0f, 0.0f, 1.0f}, 100.0f, &hit));
  EXPECT_NEAR(hit.t, 2.75f, 1e-5f);
  EXPECT_EQ(scene.shapes[hit.shape].type, ShapeType::kRoom);
  EXPECT_NEAR(hit.normal.z(), -1.0f, 1e-6f);
  // Towards the pole (cylinder at (-2, -2), r = 0.2).
  const Eigen::Vector3f from(-1.0f, -2.0f, 1.0f);
  ASSERT_TRUE(scene.Intersect(from, {-1.0f, 0.0f, 0.0f}, 100.0f, &hit));
  EXPECT_NEAR(hit.t, 0.8f, 1e-5f);
  EXPECT_NEAR(scene.ObjectClearance(from), 0.8f, 1e-5f);
  // Every hit point of random rays lies on a surface: signed distance ~ 0 for its shape.
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3f dir(std::cos(0.1f * i), std::sin(0.37f * i), std::sin(0.11f * i) - 0.3f);
    ASSERT_TRUE(scene.Intersect(from, dir.normalized(), 100.0f, &hit));
    const Eigen::Vector3f p = from + hit.t * dir.normalized();
    EXPECT_NEAR(SignedDistance(scene.shapes[hit.shape], p), 0.0f, 2e-4f);
  }
}

// The renderer tests shapes with HitLocal and asks the nearest one for its surface
// (SurfaceAtLocal): for every shape type the surface is where the hit is, its normal faces the
// ray, and (u, v) lie on the face.
TEST(Scene, HitThenSurfaceFacesTheRayOnEveryShapeType) {
  for (const ShapeType type :
       {ShapeType::kRoom, ShapeType::kBox, ShapeType::kCylinder, ShapeType::kQuad}) {
    Shape shape;
    shape.type = type;
    shape.half = type == ShapeType::kCylinder ? Eigen::Vector3f(0.4f, 0.4f, 0.7f)
                 : type == ShapeType::kQuad   ? Eigen::Vector3f(0.6f, 0.5f, 0.0f)
                                              : Eigen::Vector3f(0.6f, 0.5f, 0.7f);
    int hits = 0;
    for (int i = 0; i < 400; ++i) {
      // Rays from a sphere of radius 2 towards points near the centre (the room: from inside).
      const Eigen::Vector3f on_sphere(std::cos(0.7f * i) * std::sin(0.3f * i + 0.2f),
                                      std::sin(0.7f * i) * std::sin(0.3f * i + 0.2f),
                                      std::cos(0.3f * i + 0.2f));
      const Eigen::Vector3f o = type == ShapeType::kRoom ? Eigen::Vector3f(0.1f, -0.2f, 0.05f)
                                                         : Eigen::Vector3f(2.0f * on_sphere);
      const Eigen::Vector3f target(0.3f * std::sin(1.3f * i), 0.3f * std::cos(0.9f * i),
                                   0.3f * std::sin(0.5f * i));
      const Eigen::Vector3f d =
          type == ShapeType::kRoom ? Eigen::Vector3f(on_sphere) : Eigen::Vector3f(target - o);
      float t = 100.0f;
      int face = -1;
      if (!HitLocal(shape, o, d, 1e-4f, &t, &face)) continue;
      ++hits;
      Eigen::Vector2f uv;
      Eigen::Vector3f n;
      SurfaceAtLocal(shape, o, d, t, face, &uv, &n);
      EXPECT_NEAR(n.norm(), 1.0f, 1e-5f);
      EXPECT_LT(n.dot(d), 0.0f) << "shape type " << static_cast<int>(type) << ", face " << face;
      EXPECT_GE(face, 0);
      EXPECT_LT(face, shape.num_faces());
      EXPECT_GE(uv.x(), -1e-4f);
      EXPECT_GE(uv.y(), -1e-4f);
      const float u_max = type == ShapeType::kCylinder && face == 0
                              ? 2.0f * std::numbers::pi_v<float> * shape.half.x()
                              : 2.0f * shape.half.maxCoeff();
      EXPECT_LE(uv.x(), u_max + 1e-4f);
      EXPECT_LE(uv.y(), 2.0f * shape.half.maxCoeff() + 1e-4f);
      // IntersectLocal is the two in one call.
      float t2 = 100.0f;
      int face2 = -1;
      Eigen::Vector2f uv2;
      Eigen::Vector3f n2;
      ASSERT_TRUE(IntersectLocal(shape, o, d, 1e-4f, &t2, &face2, &uv2, &n2));
      EXPECT_EQ(t2, t);
      EXPECT_EQ(face2, face);
      EXPECT_EQ(uv2, uv);
      EXPECT_EQ(n2, n);
    }
    EXPECT_GT(hits, 100) << "shape type " << static_cast<int>(type);
  }
}

}  // namespace
}  // namespace pkslam::sim
