// What a run can tell about its own trajectory without ground truth. A trajectory that lost
// tracking for good (a new map started, or the map was reset) is stitched from maps that were
// built apart and joined later by a map merge, if at all; in the PKS study every run whose
// ATE exceeded 0.1 m was such a run, and no other run was (docs/robustness.md "Suspect
// estimates"). The run says so in its summary line and in stats.json ("estimate" object,
// "suspect": true) instead of passing for a clean one; `pkslam run --strict` exits 4.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loopclosing/loop_closing.h"
#include "tracking/tracker.h"

namespace pkslam {

struct EstimateHealth {
  // Times (s) at which tracking was lost for good: the tracker went from tracking (OK or
  // RECENTLY_LOST) to LOST or NOT_INITIALIZED, i.e. it started a new map or reset.
  std::vector<double> lost_for_good_s;
  int maps_at_end = 0;
  double largest_merge_correction_m = 0;  // how far a merge moved its query keyframe
  std::vector<std::string> warnings;
  // Why the run has no estimate at all (too few frames with a pose; NoEstimateReason), or "".
  // Such a run is an error whatever --strict says: `pkslam run` exits kExitNoEstimate.
  std::string no_estimate;

  bool suspect() const { return !warnings.empty() || !no_estimate.empty(); }
};

// "" when `poses` frames with a pose of `frames` read are an estimate; else why not. A run needs
// min(frames, 3) poses below 20 frames and 10% of its frames (at least 3) from there: fewer
// cannot even be aligned to ground truth (pkslam eval needs 3), and a tenth of a run is a
// fragment, not a trajectory. `never_initialised`: no frame ever left NOT_INITIALIZED.
std::string NoEstimateReason(int frames, int poses, bool never_initialised, bool monocular);

// Times (s) at which tracking was lost for good in `records` (frame order).
std::vector<double> LostForGoodTimes(const std::vector<FrameRecord>& records);

// The assessment: one warning per loss for good (at most kMaxLossWarnings, then a count),
// naming the merge that joined the new map back when there was one, and one when maps
// stayed apart at the end.
EstimateHealth AssessEstimate(const std::vector<double>& lost_for_good_s,
                              const std::vector<LoopEvent>& merges, int maps_at_end);

inline constexpr std::size_t kMaxLossWarnings = 5;

// Localisation only (--localise-only): tracking never starts a map, so a loss is not "for good";
// the frame after it relocalises against the loaded map or stays without a pose. One gap per
// stretch without a pose: where it began (the first frame when the run starts lost, as
// localisation does), where tracking came back (relocalised), and its length in frames.
struct LocalisationGap {
  double begin_s = 0;
  std::optional<double> relocalised_s;  // none: not relocalised before the run ended
  int frames = 0;
};
std::vector<LocalisationGap> LocalisationGaps(const std::vector<FrameRecord>& records);

}  // namespace pkslam
