#include "tracking/map_initializer.h"

#include <memory>

#include "core/bow/vocabulary.h"
#include "core/util/error.h"
#include "map_model/atlas.h"
#include "map_model/estimation/bundle_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"

namespace pkslam {

bool CanStartDepthMap(const Frame& frame, const TrackingOptions& options) {
  if (frame.size() <= options.min_features_stereo_init) return false;
  int with_depth = 0;
  for (int i = 0; i < frame.size(); ++i) with_depth += frame.HasDepth(i) ? 1 : 0;
  return with_depth >= options.min_depth_points_stereo_init;
}

DepthMapStart StartDepthMap(const MapWriteLock& lock, Atlas* atlas, const Vocabulary& vocabulary,
                            const AttachKeyFrame& attach, Frame* frame) {
  RequireWriteLock(lock, "StartDepthMap");
  DepthMapStart start;
  Map* map = atlas->current_map();
  frame->SetPose(SE3d());
  frame->ComputeBoW(vocabulary);
  start.keyframe = std::make_shared<KeyFrame>(atlas->NextKeyFrameId(), *frame, map);
  KeyFrame* kf = start.keyframe.get();
  map->AddKeyFrame(lock, start.keyframe);
  attach(lock, kf, nullptr, *frame);
  for (int i = 0; i < frame->size(); ++i) {
    const auto p = frame->UnprojectStereo(i);
    if (!p) continue;
    frame->map_points[i] = map->CreateMapPoint(lock, atlas->NextMapPointId(), *p, kf, {{kf, i}});
    ++start.points;
  }
  return start;
}

std::optional<TwoViewResult> TwoViewStart::Offer(const Frame& frame, std::uint64_t seed) {
  if (!first_) {
    if (frame.size() <= kMinFeatures) return std::nullopt;
    first_ = frame;
    last_matched_.clear();
    for (const auto& kp : frame.keypoints_undistorted()) last_matched_.push_back(kp.pt);
    matches_.assign(frame.size(), -1);
    return std::nullopt;
  }
  if (frame.size() <= kMinFeatures) {
    first_.reset();
    return std::nullopt;
  }
  const OrbMatcher matcher(0.9, true);
  const int n = matcher.SearchForInitialization(*first_, frame, &last_matched_, &matches_, 100);
  if (n < kMinFeatures) {
    first_.reset();
    return std::nullopt;
  }
  TwoViewOptions two_view;
  two_view.seed = seed;
  auto reconstruction = ReconstructTwoView(*first_, frame, matches_, two_view);
  if (!reconstruction) return std::nullopt;
  for (std::size_t i = 0; i < matches_.size(); ++i) {
    if (matches_[i] >= 0 && !reconstruction->triangulated[i]) matches_[i] = -1;
  }
  return reconstruction;
}

TwoViewKeyFrames CreateTwoViewMap(const MapWriteLock& lock, Atlas* atlas,
                                  const Vocabulary& vocabulary, const AttachKeyFrame& attach,
                                  const TwoViewResult& reconstruction,
                                  const std::vector<int>& matches, Frame* first, Frame* second) {
  RequireWriteLock(lock, "CreateTwoViewMap");
  PKSLAM_CHECK(matches.size() == reconstruction.points.size(),
               "CreateTwoViewMap: {} matches for {} reconstructed keypoints", matches.size(),
               reconstruction.points.size());
  Map* map = atlas->current_map();
  first->SetPose(SE3d());
  second->SetPose(reconstruction.camera2_from_camera1);
  first->ComputeBoW(vocabulary);
  second->ComputeBoW(vocabulary);
  TwoViewKeyFrames out;
  out.first = std::make_shared<KeyFrame>(atlas->NextKeyFrameId(), *first, map);
  out.second = std::make_shared<KeyFrame>(atlas->NextKeyFrameId(), *second, map);
  map->AddKeyFrame(lock, out.first);
  map->AddKeyFrame(lock, out.second);
  attach(lock, out.first.get(), nullptr, *first);
  attach(lock, out.second.get(), out.first.get(), *second);
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const int j = matches[i];
    if (j < 0) continue;
    second->map_points[j] = map->CreateMapPoint(
        lock, atlas->NextMapPointId(), reconstruction.points[i], out.second.get(),
        {{out.first.get(), static_cast<int>(i)}, {out.second.get(), j}});
    second->outliers[j] = 0;
  }
  out.first->UpdateConnections(lock);
  out.second->UpdateConnections(lock);
  return out;
}

void RefineTwoViewMap(Atlas* atlas) {
  BundleProblem problem;
  {
    auto lock = MapReader(*atlas).Lock();
    problem = CollectGlobalBundle(lock, *atlas->current_map());
  }
  BundleAdjustmentOptions ba;
  ba.iterations_first = 20;
  ba.iterations_second = 0;
  const BundleResult result = SolveBundle(problem, ba);
  auto lock = MapEditor(atlas).Write(MapEdit::kInitialise);
  ApplyBundle(lock, atlas->current_map(), problem, result);
}

TwoViewScaling NormaliseTwoViewScale(const MapWriteLock& lock, const TwoViewKeyFrames& map,
                                     int min_points, Frame* second) {
  RequireWriteLock(lock, "NormaliseTwoViewScale");
  TwoViewScaling scaling;
  scaling.median_depth = map.first->SceneDepthQuantile(0.5);
  if (scaling.median_depth <= 0 || map.second->TrackedMapPoints(1) < min_points) return scaling;
  const double scale = 1.0 / scaling.median_depth;
  SE3d tcw = map.second->camera_from_world();
  tcw.translation() *= scale;
  map.second->SetPose(lock, tcw);
  for (const auto& mp : map.first->map_points()) {
    if (mp && !mp->IsBad()) {
      mp->SetPosition(lock, mp->position() * scale);
      mp->UpdateNormalAndDepth(lock);
    }
  }
  second->SetPose(tcw);
  scaling.accepted = true;
  return scaling;
}

}  // namespace pkslam
