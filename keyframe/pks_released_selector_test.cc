// pks-released against the authors' released Tracking.cc, behaviour by behaviour, on a scene
// whose angles, counts, threshold and ECOG are worked out by hand below.
#include "keyframe/pks_released_selector.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/util/error.h"
#include "keyframe/selector_factory.h"

namespace pkslam {
namespace {

constexpr double kF = 400.0;
constexpr double kCx = 376.0;
constexpr double kCy = 240.0;

// A camera at `center` looking straight down (camera z = world -z, camera y = world -y):
// a point (x, y, z) projects to u = cx + f (x - Cx) / (Cz - z), v = cy - f (y - Cy) / (Cz - z).
SE3d LookingDown(const Eigen::Vector3d& center) {
  Eigen::Matrix3d world_from_camera_r = Eigen::Vector3d(1, -1, -1).asDiagonal();
  return SE3d(world_from_camera_r, center).Inverse();
}

struct ScenePoint {
  MapPointId id;
  Eigen::Vector3d position;
  Descriptor descriptor;
};

Descriptor DescriptorOf(int k) {
  Descriptor d;
  for (int i = 0; i < 32; ++i)
    d.bytes[i] = static_cast<std::uint8_t>((k * 37 + i * 11) * 2654435761u >> 24);
  return d;
}

// Flips the first `bits` bits.
Descriptor Flipped(Descriptor d, int bits) {
  for (int b = 0; b < bits; ++b) d.bytes[b / 8] ^= static_cast<std::uint8_t>(1u << (b % 8));
  return d;
}

// Four horizontal 3x3 patches (2 cm apart, slightly irregular so the released code's raw sum of
// neighbour cross products does not cancel): normals +-z, so with the released z-reflection a
// point's viewing angle is atan(horizontal distance / height difference) to the camera.
//   TL (-0.6, 0.4, 1) and BR (0.6, -0.4, 1): horizontal distance 0.721 from the z axis
//   TR (1.8, 1.2, -2) and BL (-1.8, -1.2, -2): horizontal distance 2.163
std::vector<ScenePoint> Scene() {
  const std::vector<Eigen::Vector3d> centers = {
      {-0.6, 0.4, 1}, {1.8, 1.2, -2}, {-1.8, -1.2, -2}, {0.6, -0.4, 1}};
  std::vector<ScenePoint> out;
  MapPointId id = 0;
  for (const auto& c : centers) {
    for (int a = -1; a <= 1; ++a) {
      for (int b = -1; b <= 1; ++b) {
        const Eigen::Vector3d p =
            c + Eigen::Vector3d(0.02 * a + 0.002 * b * b, 0.02 * b + 0.003 * a, 0);
        out.push_back({id, p, DescriptorOf(static_cast<int>(id))});
        ++id;
      }
    }
  }
  return out;
}

SelectorInput Input(const std::vector<ScenePoint>& points, const Eigen::Vector3d& center,
                    FrameId frame) {
  SelectorInput in;
  in.sensor = Sensor::kStereo;
  in.fps = 20;
  in.image_width = 752;
  in.image_height = 480;
  in.fx = in.fy = kF;
  in.cx = kCx;
  in.cy = kCy;
  in.bounds = {0, 752, 0, 480};
  in.frame_id = frame;
  in.t_ns = frame * 50'000'000;
  in.last_keyframe_frame_id = 0;
  in.last_keyframe_t_ns = 0;
  in.last_keyframe_camera_from_world = LookingDown({0, 0, 20});
  in.keyframes_in_map = 10;
  in.inliers = static_cast<int>(points.size());
  in.local_mapping_idle = true;
  in.camera_from_world = LookingDown(center);
  int k = 0;
  for (const ScenePoint& s : points) {
    const Eigen::Vector3d c = in.camera_from_world * s.position;
    SelectorPoint p;
    p.id = s.id;
    p.position_world = s.position;
    p.uv = Eigen::Vector2d(kF * c.x() / c.z() + kCx, kF * c.y() / c.z() + kCy);
    p.keypoint_index = k++;
    p.in_last_keyframe = true;
    p.map_point_descriptor = &s.descriptor;
    in.points.push_back(p);
  }
  return in;
}

PksOptions Options() {
  PksOptions o;
  o.weak_tracking_ratio = 0;
  return o;
}

const Eigen::Vector3d kKeyframe{0, 0, 20};
// Frame 1 (the reference) at height 10: TL/BR atan(0.721 / 9) = 4.6 deg (region 0, as from
// the keyframe: atan(0.721 / 19) = 2.2), TR/BL atan(2.163 / 12) = 10.2 deg (region 1; from the
// keyframe atan(2.163 / 22) = 5.6, region 0): D_r = 18, M_r = A_r = 36.
const Eigen::Vector3d kReference{0, 0, 10};
// Frame 2 at height 2: TL/BR atan(0.721 / 1) = 35.8 deg (region 3, changed by 33.6 > 30:
// effective), TR/BL atan(2.163 / 4) = 28.4 deg (region 2, changed by 22.8: not effective).
const Eigen::Vector3d kCurrent{0, 0, 2};

TEST(PksReleased, HandWorkedSceneFiresTheCameraCriterion) {
  const auto scene = Scene();
  PksReleasedSelector s(Options());
  s.OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  const auto r = s.Decide(Input(scene, kReference, 1));
  EXPECT_EQ(r.trace.at("M_c"), 36);
  EXPECT_EQ(r.trace.at("D_c"), 18);
  EXPECT_EQ(r.trace.at("E_c"), 0);
  EXPECT_FALSE(r.insert);  // criterion 1 needs frames > 1

  const auto d = s.Decide(Input(scene, kCurrent, 2));
  EXPECT_EQ(d.trace.at("A_c"), 36);
  EXPECT_EQ(d.trace.at("M_c"), 36);
  EXPECT_EQ(d.trace.at("D_c"), 36);
  EXPECT_EQ(d.trace.at("E_c"), 18);  // TL and BR
  EXPECT_EQ(d.trace.at("A_r"), 36);
  EXPECT_EQ(d.trace.at("M_r"), 36);
  EXPECT_EQ(d.trace.at("D_r"), 18);
  // Th_initial = (36 * 18 / 36 + 36 * 18 / 36) / 2 = 18; theta = 0 < 0.1: Th = 1.1 * 18.
  EXPECT_DOUBLE_EQ(d.trace.at("Th_initial"), 18.0);
  EXPECT_DOUBLE_EQ(d.trace.at("Th_adaptive"), 1.1 * 18.0);
  // Effective points: 9 in the top-left cell, 9 in the bottom-right one: d = 2 sqrt 2,
  // ECOG = 2 sqrt 2 * 9 / (2 sqrt 2 * 9) = 1; centre of gravity (0, 0).
  EXPECT_NEAR(d.trace.at("ECOG"), 1.0, 1e-12);
  EXPECT_NEAR(d.trace.at("COG"), 0.0, 1e-12);
  EXPECT_TRUE(d.insert);
  EXPECT_EQ(d.reason, "camera");
}

TEST(PksReleased, LateDenominatorAfterFourFrames) {
  const auto scene = Scene();
  PksReleasedSelector s(Options());
  s.OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  s.Decide(Input(scene, kReference, 1));
  // Frame 5: denominator sqrt 2 * max1, ECOG = 2 sqrt 2 * 9 / (sqrt 2 * 9) = 2.
  const auto d = s.Decide(Input(scene, kCurrent, 5));
  EXPECT_NEAR(d.trace.at("ECOG"), 2.0, 1e-12);
}

TEST(PksReleased, PairsByReprojectionAndDescriptorNotByIdentity) {
  const auto scene = Scene();
  // The frame sees the same places as new map points (other ids) whose descriptors differ by
  // 5 bits: reprojection pairing finds all 36; identity pairing none.
  std::vector<ScenePoint> renamed = scene;
  for (auto& p : renamed) {
    p.id += 1000;
    p.descriptor = Flipped(p.descriptor, 5);
  }
  // Three are too far in descriptor space (Hamming 30, not below 30), one keypoint lies
  // 10 px from the projection (outside the +-10 px window: |du| < 10 is required).
  for (int i : {0, 1, 2}) renamed[i].descriptor = Flipped(scene[i].descriptor, 30);
  auto frame = Input(renamed, kReference, 1);
  frame.points[3].uv.x() += 10.0;
  frame.points[4].uv.x() += 9.5;  // still inside

  PksReleasedSelector reprojection(Options());
  reprojection.OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  EXPECT_EQ(reprojection.Decide(frame).trace.at("M_c"), 32);

  PksOptions o = Options();
  o.identity_pairing = true;
  PksReleasedSelector identity(o);
  identity.OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  EXPECT_EQ(identity.Decide(frame).trace.at("M_c"), 0);
  // The same ids pair by identity whatever their descriptor.
  auto same = Input(scene, kReference, 1);
  std::vector<Descriptor> far;
  for (const auto& p : same.points) far.push_back(Flipped(*p.map_point_descriptor, 100));
  for (std::size_t i = 0; i < far.size(); ++i) same.points[i].map_point_descriptor = &far[i];
  EXPECT_EQ(identity.Decide(same).trace.at("M_c"), 36);
}

TEST(PksReleased, NeighbouringPointPairsWhenItsDescriptorIsCloser) {
  const auto scene = Scene();
  // Frame: point 0 is gone; a new map point (id 500) whose keypoint lies 2 px from point 0's
  // projection, with a descriptor at Hamming 3 from it, takes its place: it pairs.
  std::vector<ScenePoint> frame_points(scene.begin() + 1, scene.end());
  frame_points.push_back({500, scene[0].position, Flipped(scene[0].descriptor, 3)});
  PksReleasedSelector s(Options());
  s.OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  auto in = Input(frame_points, kReference, 1);
  in.points.back().uv.x() += 2.0;
  EXPECT_EQ(s.Decide(in).trace.at("M_c"), 36);
}

TEST(PksReleased, OutliersCountInAAndInTheSnapshot) {
  const auto scene = Scene();
  PksReleasedSelector s(Options());
  EXPECT_TRUE(s.NeedsOutliers());
  EXPECT_TRUE(s.SnapshotAfterCreation());
  auto kf = Input(scene, kKeyframe, 0);
  for (int i = 0; i < 9; ++i) kf.points[i].outlier = true;
  s.OnKeyFrameInserted(kf);
  auto frame = Input(scene, kReference, 1);
  for (int i = 0; i < 9; ++i) frame.points[i].outlier = true;
  const auto r = s.Decide(frame);
  EXPECT_EQ(r.trace.at("A_c"), 36);
  EXPECT_EQ(r.trace.at("M_c"), 36);
}

TEST(PksReleased, NoChangeReturnsBeforeTheReferenceSoTheOldOneSurvives) {
  const auto scene = Scene();
  PksReleasedSelector s(Options());
  s.OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  // Frame 1 at the keyframe's place: D = 0, no reference taken.
  const auto r = s.Decide(Input(scene, kKeyframe + Eigen::Vector3d(0, 0, -0.5), 1));
  EXPECT_EQ(r.trace.at("D_c"), 0);
  const auto d = s.Decide(Input(scene, kCurrent, 2));
  EXPECT_EQ(d.trace.count("A_r"), 0u);  // no reference ever: no criterion 1
  EXPECT_FALSE(d.insert);

  // With a reference from the interval before, a keyframe whose frame 1 returns early keeps it.
  PksReleasedSelector t(Options());
  t.OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  t.Decide(Input(scene, kReference, 1));  // reference D_r = 18
  t.OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  t.Decide(Input(scene, kKeyframe + Eigen::Vector3d(0, 0, -0.5), 1));
  const auto e = t.Decide(Input(scene, kCurrent, 2));
  EXPECT_EQ(e.trace.at("D_r"), 18);
  EXPECT_TRUE(e.insert);
}

TEST(PksReleased, FrozenNormalsAblationUsesTheKeyframeNormals) {
  // With per-frame normals and with the keyframe's, a horizontal patch has the same normal:
  // the counts agree on this scene (the ablation changes results only where re-estimated
  // normals wander).
  const auto scene = Scene();
  PksOptions o = Options();
  o.frozen_normals = true;
  PksReleasedSelector s(o);
  s.OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  s.Decide(Input(scene, kReference, 1));
  const auto d = s.Decide(Input(scene, kCurrent, 2));
  EXPECT_EQ(d.trace.at("D_c"), 36);
  EXPECT_EQ(d.trace.at("E_c"), 18);
}

TEST(PksReleased, ForcedKeyframeAtExactlySixFramesUnlessAblated) {
  const auto scene = Scene();
  PksReleasedSelector s(Options());
  PksOptions o = Options();
  o.forced_interval = 0;
  PksReleasedSelector ablated(o);
  for (auto* sel : {&s, &ablated}) sel->OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  for (FrameId f : {5, 6, 7}) {
    const auto in = Input(scene, kKeyframe + Eigen::Vector3d(0, 0, -0.5), f);
    const auto d = s.Decide(in);
    EXPECT_EQ(d.insert, f == 6) << f;
    if (f == 6) {
      EXPECT_EQ(d.reason, "forced");
    }
    EXPECT_FALSE(ablated.Decide(in).insert) << f;
  }
}

TEST(PksReleased, ExitsOfTheReleasedCode) {
  const auto scene = Scene();
  PksReleasedSelector s(Options());
  s.OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  auto in = Input(scene, kKeyframe + Eigen::Vector3d(0, 0, -0.5), 6);  // forced otherwise
  in.local_mapping_initializing = true;
  EXPECT_EQ(s.Decide(in).reason, "imu-initialising");
  // ORB-SLAM3 v1.0's reading: the keyframe is taken and waits for local mapping.
  PksOptions v1 = Options();
  v1.no_keyframe_while_imu_initialises = false;
  PksReleasedSelector t(v1);
  t.OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  in.local_mapping_idle = false;
  const auto taken = t.Decide(in);
  EXPECT_TRUE(taken.insert);
  EXPECT_EQ(taken.reason, "forced");
  in.local_mapping_idle = true;
  in.local_mapping_initializing = false;
  in.slow_motion_before_refinement = true;
  EXPECT_EQ(s.Decide(in).reason, "slow-motion");

  // The close-point rule needs local mapping idle.
  auto close = Input(scene, kKeyframe + Eigen::Vector3d(0, 0, -0.5), 3);
  close.tracked_close = 10;
  close.untracked_close = 200;
  EXPECT_EQ(s.Decide(close).reason, "close");
  close.local_mapping_idle = false;
  EXPECT_EQ(s.Decide(close).reason, "no");
}

TEST(PksReleased, ImuRuleComparesConsecutiveFrameIntervalsWithGravity) {
  const auto scene = Scene();
  auto input = [&](FrameId f, const Eigen::Vector3d& body) {
    SelectorInput in = Input(scene, kKeyframe + Eigen::Vector3d(0, 0, -0.5), f);
    in.sensor = Sensor::kStereoInertial;
    in.imu_initialized = true;
    in.t_ns = 100'000'000;  // below the 0.5 s time rule
    SelectorImuInterval imu;
    imu.dt = 0.05;
    imu.mean_accel = body;
    in.imu_since_last_frame = imu;
    return in;
  };
  const Eigen::Vector3d g(0, 0, 9.81);
  PksReleasedSelector s(Options());
  s.OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  EXPECT_FALSE(s.Decide(input(1, g)).insert);
  EXPECT_FALSE(s.Decide(input(2, g + Eigen::Vector3d(0.8, 0, 0))).insert);
  const auto r = s.Decide(input(3, g + Eigen::Vector3d(-0.8, 0, 0)));
  EXPECT_NEAR(r.trace.at("delta_a"), 1.6, 1e-12);
  EXPECT_TRUE(r.insert);
  EXPECT_EQ(r.reason, "imu");

  PksOptions o = Options();
  o.imu_threshold = 0;  // the no-IMU ablation
  PksReleasedSelector ablated(o);
  ablated.OnKeyFrameInserted(Input(scene, kKeyframe, 0));
  ablated.Decide(input(2, g + Eigen::Vector3d(0.8, 0, 0)));
  EXPECT_FALSE(ablated.Decide(input(3, g + Eigen::Vector3d(-0.8, 0, 0))).insert);
}

TEST(PksReleased, FactoryReadsTheAblationSwitches) {
  EXPECT_EQ(MakeKeyframeSelector("pks-released", {{"identity_pairing", 1},
                                                  {"frozen_normals", 1},
                                                  {"forced_interval", 0},
                                                  {"imu_threshold", 0}})
                ->name(),
            "pks-released");
  EXPECT_THROW(MakeKeyframeSelector("pks-released", {{"identity_pairing", 0.5}}), OptionError);
  EXPECT_THROW(MakeKeyframeSelector("pks", {{"identity_pairing", 1}}), OptionError);
  EXPECT_THROW(MakeKeyframeSelector("pks-released", {{"pairing_max_hamming", 0}}), OptionError);
}

}  // namespace
}  // namespace pkslam
