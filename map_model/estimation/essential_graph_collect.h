// The map side of the essential graph (estimators/optim/essential_graph.h): Collect builds the
// pose-graph value from a map and a loop correction, Apply writes the optimised poses back
// and moves everything that follows them (points, velocities, keyframes created meanwhile).
#pragma once

#include "estimators/optim/essential_graph.h"
#include "map_model/map_ids.h"

namespace pkslam {

class MapWriteLock;

// Builds the graph over the live keyframes of `map`. Requires the Atlas mutex (shared).
EssentialGraphProblem CollectEssentialGraph(Map* map, const LoopCorrection& correction,
                                            const EssentialGraphOptions& options);
// Requires the Atlas mutex (exclusive); `map` is the map the problem was collected from. Sets each
// live vertex keyframe's pose to its optimised Sim3 with the translation divided by the scale,
// turns (and scales) valid keyframe velocities from the world of camera_from_world_before to the
// optimised one (callers leave the velocities of the corrected neighbourhood as they were), moves
// every live map point of the map with the correction S_wc(optimised) * S_cw(initial) of the
// keyframe it follows (or, for points and keyframes created after Collect, of the nearest
// spanning-tree ancestor in the graph), updates normals and depth ranges, and bumps the map's
// change index.
void ApplyEssentialGraph(const MapWriteLock& lock, Map* map, const EssentialGraphProblem& problem,
                         const EssentialGraphResult& result);

}  // namespace pkslam
