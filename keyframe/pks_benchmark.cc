// Cost of one PKS decision at ORB-SLAM3's feature count (issue 8: <= 0.3 ms median).
#include <benchmark/benchmark.h>

#include <memory>
#include <random>

#include "keyframe/pks_released_selector.h"
#include "keyframe/pks_selector.h"

namespace pkslam {
namespace {

const Descriptor kDescriptor{};

// ~1200 features of which ~800 are tracked map points on a bumpy wall 3-6 m away.
SelectorInput MakeInput(std::mt19937& rng, FrameId frame, const Eigen::Vector3d& center) {
  std::uniform_real_distribution<double> u(-3, 3), v(-2, 2), w(3, 6);
  SelectorInput in;
  in.sensor = Sensor::kStereoInertial;
  in.imu_initialized = true;
  in.fps = 20;
  in.image_width = 752;
  in.image_height = 480;
  in.fx = in.fy = 435;
  in.cx = 376;
  in.cy = 240;
  in.bounds = {0, 752, 0, 480};
  in.frame_id = frame;
  in.t_ns = frame * 50'000'000;
  in.keyframes_in_map = 20;
  in.local_mapping_idle = true;
  in.camera_from_world = SE3d(SO3d(), -center);
  in.last_keyframe_camera_from_world = SE3d();
  std::mt19937 fixed(7);  // same points every frame
  for (int i = 0; i < 800; ++i) {
    SelectorPoint p;
    p.id = i;
    p.position_world = Eigen::Vector3d(u(fixed), v(fixed), w(fixed));
    const Eigen::Vector3d c = p.position_world - center;
    p.uv = Eigen::Vector2d(435 * c.x() / c.z() + 376, 435 * c.y() / c.z() + 240);
    p.in_last_keyframe = true;
    p.keypoint_index = i;
    p.map_point_descriptor = &kDescriptor;
    in.points.push_back(p);
  }
  (void)rng;
  return in;
}

void BM_PksDecision(benchmark::State& state) {
  const bool released = state.range(0) != 0;
  std::mt19937 rng(1);
  std::unique_ptr<KeyframeSelector> selector_owner =
      released ? std::unique_ptr<KeyframeSelector>(new PksReleasedSelector(PksOptions{}))
               : std::unique_ptr<KeyframeSelector>(new PksSelector(PksOptions{}));
  KeyframeSelector& selector = *selector_owner;
  selector.OnKeyFrameInserted(MakeInput(rng, 0, Eigen::Vector3d::Zero()));
  const SelectorInput first = MakeInput(rng, 1, Eigen::Vector3d(0.01, 0, 0));
  selector.Decide(first);
  const SelectorInput in = MakeInput(rng, 3, Eigen::Vector3d(0.3, 0.05, 0.1));
  for (auto _ : state) benchmark::DoNotOptimize(selector.Decide(in));
  state.SetLabel(released ? "pks-released (reprojection pairing, normals every frame)" : "pks");
}
BENCHMARK(BM_PksDecision)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_PksKeyframeSnapshot(benchmark::State& state) {
  std::mt19937 rng(1);
  PksSelector selector(PksOptions{});
  const SelectorInput in = MakeInput(rng, 0, Eigen::Vector3d::Zero());
  for (auto _ : state) selector.OnKeyFrameInserted(in);
}
BENCHMARK(BM_PksKeyframeSnapshot)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace pkslam
