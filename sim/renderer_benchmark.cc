// Rendering speed of a stereo frame (both EuRoC cameras, 752x480, default quality: 1024
// textures, one ray per pixel) in the Vicon room and the machine hall, along a medium random
// flight: ray casting + shading + image formation. Run: build/benchmarks/pkslam_sim_benchmark.
// With 1 thread, the CPU column is the cost per frame on one core; the 2-core throughput is
// about twice its rate (tiles are independent). On a loaded machine, trust CPU, not Time.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <string>

#include "sim/euroc_writer.h"
#include "sim/motion_generator.h"
#include "sim/renderer.h"
#include "sim/scene_builder.h"
#include "sim/sensor_model.h"

namespace pkslam::sim {
namespace {

struct Fixture {
  Scene scene;
  SplineTrajectory trajectory;
  CameraRig left = EurocCam0();
  CameraRig right = EurocCam1();

  explicit Fixture(const std::string& scene_name) {
    SceneBuildOptions o;
    o.texture_size = 1024;
    scene = BuildScene(LoadSceneDescription(scene_name), o, {});
    MotionOptions m;
    m.duration_s = 30;
    trajectory = GenerateMotion(scene, m, left.body_from_camera, 1, 0);
  }
};

void BM_StereoFrame(benchmark::State& state) {
  const tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(state.range(0)));
  const Fixture f(state.range(1) == 0 ? "vicon_room" : "machine_hall");
  const Renderer renderer(f.scene, RenderOptions());
  const CameraRays rays_l(f.left.camera);
  const CameraRays rays_r(f.right.camera);
  SensorModel sensor_l(SensorOptions(), rays_l, 1);
  SensorModel sensor_r(SensorOptions(), rays_r, 2);
  RenderBuffers bl, br;
  std::int64_t t = 3'000'000'000;
  std::uint64_t frame = 0;
  for (auto _ : state) {
    const SE3d body = f.trajectory.WorldFromBody(t);
    renderer.Render(rays_l, body * f.left.body_from_camera, &bl);
    renderer.Render(rays_r, body * f.right.body_from_camera, &br);
    const double gain = sensor_l.NextGain(bl.radiance, 0.05);
    benchmark::DoNotOptimize(sensor_l.Develop(bl.radiance, gain, frame));
    benchmark::DoNotOptimize(sensor_r.Develop(br.radiance, gain, frame));
    t += 50'000'000;
    if (t > 28'000'000'000) t = 3'000'000'000;
    ++frame;
  }
  state.counters["stereo_fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
// Args: threads, scene (0 = vicon_room, 1 = machine_hall).
BENCHMARK(BM_StereoFrame)
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({1, 1})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace pkslam::sim
