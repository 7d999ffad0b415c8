// Matcher timings on the synthetic fixture: local-map projection of ~2000 points into a frame
// of 1200 keypoints (the per-frame hot path of tracking), the motion-model search, and the
// BoW / triangulation searches with a k=10, L=3 vocabulary (direct index at level 2, ~100
// nodes, the grouping ORBvoc gives).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <mutex>
#include <shared_mutex>

#include "core/util/log.h"
#include "map_model/map_editor.h"
#include "map_model/matching/matching_test_utils.h"
#include "map_model/matching/orb_matcher.h"

namespace pkslam {
namespace {

using testing::EditFrame;
using testing::FrameOptions;
using testing::MakeForwardPath;
using testing::MakeMap;
using testing::MakePosedFrame;
using testing::MakeScene;
using testing::MakeStereoRig;
using testing::ProjectMapPoints;

constexpr int kKeypoints = 1200;
constexpr std::size_t kProjected = 2000;

// The first n keypoints of a frame (the fixture emits them in scene order, i.e. spread out).
Frame Truncate(const Frame& f, int n, std::vector<int>* pok) {
  Frame out = EditFrame(f, [n](FrameFeatures* ff) {
    const auto keep = static_cast<std::size_t>(n);
    ff->keypoints.resize(std::min(keep, ff->keypoints.size()));
    ff->descriptors.resize(ff->keypoints.size());
    if (!ff->right_u.empty()) ff->right_u.resize(ff->keypoints.size());
    if (!ff->depth.empty()) ff->depth.resize(ff->keypoints.size());
  });
  pok->resize(static_cast<std::size_t>(out.size()));
  out.SetPose(f.camera_from_world());
  return out;
}

struct Fixture {
  std::shared_ptr<CameraRig> rig = MakeStereoRig();
  testing::SyntheticScene scene = MakeScene(4000, 7);
  std::vector<SE3d> poses = MakeForwardPath(4, 0.15, 8);
  Atlas atlas;
  testing::SyntheticMap map;
  Frame frame;
  std::vector<int> pok;
  Frame last;
  std::vector<ProjectedPoint> projected;

  Fixture() {
    FrameOptions o;
    o.pixel_noise = 0.5;
    o.descriptor_bit_flips = 8;
    map = MakeMap(&atlas, scene, rig, {poses[0], poses[1], poses[2]}, o);
    o.seed = 5;
    frame = Truncate(MakePosedFrame(scene, rig, poses[3], 100, o, &pok), kKeypoints, &pok);
    std::vector<int> pok_last;
    last = Truncate(MakePosedFrame(scene, rig, poses[2], 99, o, &pok_last), kKeypoints, &pok_last);
    for (int i = 0; i < last.size(); ++i)
      last.map_points[i] = map.point_of_scene_index[pok_last[i]];
    std::vector<MapPointPtr> points;
    for (const auto& p : map.point_of_scene_index) {
      if (p) points.push_back(p);
    }
    projected = ProjectMapPoints(points, frame);
    if (projected.size() > kProjected) projected.resize(kProjected);
  }
};

void BM_SearchByProjectionLocalMap(benchmark::State& state) {
  Fixture fx;  // rebuilt per run (no statics); not timed
  auto lock = MapReader(fx.atlas).Lock();
  Frame frame = fx.frame;
  const OrbMatcher matcher(0.8);
  int matches = 0;
  for (auto _ : state) {
    std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
    matches = matcher.SearchByProjection(&frame, fx.projected, 1.0);
    benchmark::DoNotOptimize(matches);
  }
  state.counters["projected"] = static_cast<double>(fx.projected.size());
  state.counters["keypoints"] = frame.size();
  state.counters["matches"] = matches;
}
BENCHMARK(BM_SearchByProjectionLocalMap)->Unit(benchmark::kMicrosecond);

// The grid queries alone of the local-map search (one allocated vector per point): the share
// of BM_SearchByProjectionLocalMap spent in Frame::FeaturesInArea.
void BM_FeaturesInAreaLocalMap(benchmark::State& state) {
  Fixture fx;
  const auto& scale = fx.rig->pyramid.scale;
  std::size_t found = 0;
  for (auto _ : state) {
    found = 0;
    for (const ProjectedPoint& p : fx.projected) {
      const double r = OrbMatcher::RadiusByViewingCos(p.view_cos) * scale[p.predicted_level];
      found +=
          fx.frame.FeaturesInArea(p.u, p.v, r, p.predicted_level - 1, p.predicted_level).size();
    }
    benchmark::DoNotOptimize(found);
  }
  state.counters["candidates"] = static_cast<double>(found);
}
BENCHMARK(BM_FeaturesInAreaLocalMap)->Unit(benchmark::kMicrosecond);

void BM_SearchByProjectionMotionModel(benchmark::State& state) {
  Fixture fx;  // rebuilt per run (no statics); not timed
  auto lock = MapReader(fx.atlas).Lock();
  Frame frame = fx.frame;
  const OrbMatcher matcher(0.9);
  int matches = 0;
  for (auto _ : state) {
    std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
    matches = matcher.SearchByProjection(&frame, fx.last, 7.0, false);
    benchmark::DoNotOptimize(matches);
  }
  state.counters["last_points"] = fx.last.NumTrackedMapPoints();
  state.counters["matches"] = matches;
}
BENCHMARK(BM_SearchByProjectionMotionModel)->Unit(benchmark::kMicrosecond);

// BoW searches need keyframes with feature vectors: built from frames with BoW.
struct BowFixture {
  Vocabulary vocabulary;
  KeyFramePtr kf1;       // with the map points of its keypoints (BoW search)
  KeyFramePtr kf1_bare;  // the same frame without map points, and
  KeyFramePtr kf2;       // the next one, for triangulation
  Frame frame;

  explicit BowFixture(Fixture& fx) {
    SetLogLevel("warn");  // vocabulary training reports at info level on every rebuild
    std::vector<std::vector<Descriptor>> images;
    for (const auto& kf : fx.map.keyframes) images.push_back(kf->descriptors());
    VocabularyTrainOptions options;
    options.branching = 10;
    options.levels = 3;
    options.weighting = Weighting::kTf;
    options.quiet = true;
    vocabulary = Vocabulary::Train(images, options);
    FrameOptions o;
    o.descriptor_bit_flips = 8;
    std::vector<int> pok1;
    std::vector<int> pok2;
    auto lock = MapEditor(&fx.atlas).Write(MapEdit::kFixture);
    Frame f1 =
        Truncate(MakePosedFrame(fx.scene, fx.rig, fx.poses[1], 200, o, &pok1), kKeypoints, &pok1);
    Frame f2 =
        Truncate(MakePosedFrame(fx.scene, fx.rig, fx.poses[2], 201, o, &pok2), kKeypoints, &pok2);
    f1.ComputeBoW(vocabulary);
    f2.ComputeBoW(vocabulary);
    kf1 = std::make_shared<KeyFrame>(1000, f1, fx.atlas.current_map());
    kf1_bare = std::make_shared<KeyFrame>(1001, f1, fx.atlas.current_map());
    kf2 = std::make_shared<KeyFrame>(1002, f2, fx.atlas.current_map());
    // kf1 observes the map points of its keypoints (for keyframe-frame BoW search).
    for (int i = 0; i < kf1->size(); ++i) {
      kf1->AddMapPoint(lock, fx.map.point_of_scene_index[pok1[i]], i);
    }
    frame = fx.frame;
    frame.ComputeBoW(vocabulary);
  }
};

void BM_SearchByBoWKeyFrameFrame(benchmark::State& state) {
  Fixture fx;
  BowFixture bx(fx);
  auto lock = MapReader(fx.atlas).Lock();
  const OrbMatcher matcher(0.75);
  std::vector<MapPointPtr> matches;
  int n = 0;
  for (auto _ : state) {
    n = matcher.SearchByBoW(*bx.kf1, bx.frame, &matches);
    benchmark::DoNotOptimize(n);
  }
  state.counters["nodes"] = static_cast<double>(bx.kf1->feature_vector().size());
  state.counters["matches"] = n;
}
BENCHMARK(BM_SearchByBoWKeyFrameFrame)->Unit(benchmark::kMicrosecond);

void BM_SearchForTriangulation(benchmark::State& state) {
  Fixture fx;
  BowFixture bx(fx);
  auto lock = MapReader(fx.atlas).Lock();
  const OrbMatcher matcher(0.6);
  std::size_t n = 0;
  for (auto _ : state) {
    n = matcher.SearchForTriangulation(*bx.kf1_bare, *bx.kf2).size();
    benchmark::DoNotOptimize(n);
  }
  state.counters["pairs"] = static_cast<double>(n);
}
BENCHMARK(BM_SearchForTriangulation)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace pkslam
