// Merging a global bundle adjustment back into a map that kept growing while it ran
// (ORB-SLAM3's RunGlobalBundleAdjustment write-back): keyframes and points of the problem get
// their optimised values; keyframes created meanwhile follow their spanning-tree parent
// (keeping their pose relative to it) and points created meanwhile follow their reference
// keyframe.
#pragma once

#include "core/optim/bundle_adjustment.h"

namespace pkslam {

// Requires the Atlas mutex (exclusive). Keyframes and points no longer in `map` are left
// alone. Bumps the map's change index.
void MergeGlobalBundle(Map* map, const BundleProblem& problem, const BundleResult& result);

}  // namespace pkslam
