#include "tracking/map_starter.h"

#include <utility>

#include "core/util/log.h"
#include "map_model/atlas.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"

namespace pkslam {

int StartedMap::TrackedPoints() const {
  return depth_points ? *depth_points : newest()->TrackedMapPoints(1);
}

StartedMap MapStarter::Offer(Frame* current, const AttachKeyFrame& attach, LocalMap* local_map) {
  if (!monocular_) return StartFromDepth(current, attach, local_map);
  const auto reconstruction =
      two_view_.Offer(*current, MixSeed(options_.seed, static_cast<std::uint64_t>(current->id())));
  if (!reconstruction) return {};
  return StartFromTwoViews(*reconstruction, current, attach, local_map);
}

StartedMap MapStarter::StartFromDepth(Frame* current, const AttachKeyFrame& attach,
                                      LocalMap* local_map) {
  if (!CanStartDepthMap(*current, options_)) return {};
  DepthMapStart start;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInitialise);
    start = StartDepthMap(lock, atlas_, *vocabulary_, attach, current);
    local_map->Reset({start.keyframe.get()}, start.keyframe->GoodMapPoints());
  }
  PKSLAM_LOG_INFO("new map {} initialised from stereo/depth with {} points",
                  atlas_->current_map()->id(), start.points);
  StartedMap started;
  started.keyframes = {start.keyframe};
  started.depth_points = start.points;
  return started;
}

StartedMap MapStarter::StartFromTwoViews(const TwoViewResult& reconstruction, Frame* current,
                                         const AttachKeyFrame& attach, LocalMap* local_map) {
  TwoViewKeyFrames map;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInitialise);
    map = CreateTwoViewMap(lock, atlas_, *vocabulary_, attach, reconstruction, two_view_.matches(),
                           &two_view_.first(), current);
  }
  // Refine both views and all points before fixing the scale.
  RefineTwoViewMap(atlas_);
  StartedMap started;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInitialise);
    const TwoViewScaling scaling =
        NormaliseTwoViewScale(lock, map, options_.min_two_view_map_points, current);
    if (!scaling.accepted) {
      lock.unlock();
      PKSLAM_LOG_WARN("monocular initialisation rejected (median depth {:.3f}); retrying",
                      scaling.median_depth);
      started.refused = true;
      return started;
    }
    local_map->Reset({map.second.get(), map.first.get()}, map.first->GoodMapPoints());
    PKSLAM_LOG_INFO("new map {} initialised from two views with {} points",
                    atlas_->current_map()->id(), atlas_->current_map()->NumMapPoints());
  }
  started.keyframes = {map.first, map.second};
  started.first_of_pair = std::move(two_view_.first());
  two_view_.Reset();
  return started;
}

}  // namespace pkslam
